#!/usr/bin/env python3
"""The noise target's ceilings per block and per pixel (docs/benchmarks.md, "Noise target").

K uniform renders of N spp (seeds 101, 102, ...) give each pixel's variance, and so u_p, its
relative variance per sample (over the reference of bench/noise_target.py, mean over channels;
the 1/n law). A block's error is the mean of u_p / n_p over its pixels, as the rule measures it.
At any error W:
  uniform sampling gives every pixel what the neediest block needs, max_b sum(u) / (P W^2);
  the per-block ceiling gives each block its own count, sum(u) / (P W^2) for its P pixels;
  the per-pixel ceiling gives each pixel n_p proportional to sqrt(u_p) (the least samples that
      bring the block's mean to W^2), (sum sqrt(u))^2 / (P W^2) per block in all.
Each block's samples cost what they cost when it is rendered alone (measured as
bench/noise_target.py does; a block's pixels are taken to cost alike). Prints uniform's time
over each ceiling's.

  PYTHONPATH=build/python /usr/bin/python3 bench/noise_pixel_ceiling.py [--scale 0.1667]
      [--films 8] [--spp 128] [--ref-spp 4096] [--out build-noisebench] [SCENE...]
"""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import noise_target as nt  # noqa: E402

BLOCK = nt.BLOCK


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="*", default=[os.path.join(nt.ROOT, "scenes", s + ".json")
                                                 for s in ("demo", "translucent")])
    p.add_argument("--scale", type=float, default=0.1667)
    p.add_argument("--films", type=int, default=8)
    p.add_argument("--spp", type=int, default=128)
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--cost-spp", type=int, default=64)
    p.add_argument("--out", default=os.path.join(nt.ROOT, "build-noisebench"))
    args = p.parse_args()
    import nimbus
    for scene in args.scenes:
        size = nt.scene_size(scene, args.scale)
        ref, _ = nt.reference(args, scene, size)
        sc = nimbus.load_file(scene, {"film.width": size[0], "film.height": size[1]})
        films = np.array([nimbus.render(sc, spp=args.spp, seed=101 + k, threads=args.threads)
                          for k in range(args.films)], dtype=np.float64)
        m = np.maximum(np.abs(ref), nt.FLOOR)
        u = (films.var(axis=0, ddof=1) * args.spp / m ** 2).mean(axis=2)
        c = nt.block_costs(args, scene, size)
        total, sqrt_sum, pixels = (np.zeros(c.shape) for _ in range(3))
        for j in range(c.shape[0]):
            for i in range(c.shape[1]):
                b = u[j * BLOCK:(j + 1) * BLOCK, i * BLOCK:(i + 1) * BLOCK]
                total[j, i], sqrt_sum[j, i], pixels[j, i] = b.sum(), np.sqrt(b).sum(), b.size
        # Times at W = 1 (each scales as 1 / W^2 alike).
        t_uniform = (total / pixels).max() * (c * pixels).sum()
        t_block = (c * total).sum()
        t_pixel = (c * sqrt_sum ** 2 / pixels).sum()
        print(f"{os.path.basename(scene)} {size[0]}x{size[1]}, {args.films} renders of {args.spp} "
              f"spp: uniform's time over the per-block ceiling's {t_uniform / t_block:.2f}x, over "
              f"the per-pixel ceiling's {t_uniform / t_pixel:.2f}x", flush=True)


if __name__ == "__main__":
    main()
