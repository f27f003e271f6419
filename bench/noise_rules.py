#!/usr/bin/env python3
"""Stopping rules for the noise target, simulated on one scene (docs/benchmarks.md, "Noise target").

The renderer's rule decides each 8x8 block from the difference of its pixels' two halves, two
independent randomizations of the sequence (render/noise_target.h). Here the two halves are two
uniform films of seeds S and S + 1, rendered through the Python module to the rule's pass ends
(16, 32, 48, ... up to the cap) and kept at each; a rule is then replayed on them: a block that
stops at pass end n keeps the mean of both films at n/2 each, as the renderer's would. Each rule's
worst block error (against the reference of bench/noise_target.py), its CPU time (each block's
samples at the block's own cost, measured by rendering it alone) and the uniform spp with the same
worst block (interpolated between pass ends of the films' mean, log against log) give its time
saved, as bench/noise_target.py does for the renderer. --pairs repeats it with other seeds: the
worst block of one image is a single draw of a maximum, and it swings between draws.

Rules, each at the target E:
  own     the renderer's: a block stops when its estimate e = rms over its pixels and channels of
          (d/2) / max(|m|, 2^-8) is at most E (d the halves' difference, m their mean)
  twice   own, but only at the second pass end in a row at which e <= E
  row     own, and also the root mean square of e over the block and its left and right
          neighbours (a stopped neighbour at its stop) is at most E
  3x3     the same over the 3x3 blocks around it
  min     own, with the pixel's smaller half |a| or |b| in place of |m|

  PYTHONPATH=build/python /usr/bin/python3 bench/noise_rules.py [--scale 0.1667] [--cap 2048]
      [--targets 0.05 0.07 0.1] [--pairs 1] [--ref-spp 4096] [--out build-noisebench] [SCENE]
"""
import argparse
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import noise_target as nt  # noqa: E402

BLOCK, FLOOR = nt.BLOCK, nt.FLOOR
RULES = ("own", "twice", "row", "3x3", "min")


def pass_ends(cap, first=16):
    ends = [first]
    while ends[-1] < cap:
        n = ends[-1]
        ends.append(min(cap, n + max(first, 2 * (n // 8))))
    return ends


def films(args, scene, size, ends, seed):
    """Both halves' images at every pass end: arrays (pass ends, height, width, 3), cached."""
    import nimbus
    name = os.path.splitext(os.path.basename(scene))[0]
    path = os.path.join(args.out, "rules", f"{name}_{size[0]}x{size[1]}_{ends[-1]}_{seed}.npz")
    if os.path.exists(path):
        z = np.load(path)
        return z["a"].astype(np.float64), z["b"].astype(np.float64)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    sc = nimbus.load_file(scene, {"film.width": size[0], "film.height": size[1]})
    halves = []
    for s in (seed, seed + 1):
        film, images, held = nimbus.Film(sc), [], 0
        for n in ends:
            nimbus.render_into(sc, film, samples=(held, n // 2), seed=s, threads=args.threads)
            held = n // 2
            images.append(film.image())
        halves.append(np.array(images))
    np.savez(path, a=halves[0], b=halves[1])
    return halves[0].astype(np.float64), halves[1].astype(np.float64)


def block_means(values, by, bx):
    """The mean over each block's pixels and channels: (pass ends, by, bx)."""
    out = np.zeros((values.shape[0], by, bx))
    for j in range(by):
        for i in range(bx):
            out[:, j, i] = values[:, j * BLOCK:(j + 1) * BLOCK, i * BLOCK:(i + 1) * BLOCK].reshape(
                values.shape[0], -1).mean(axis=1)
    return out


def replay(rule, target, est, est_min, by, bx):
    """Each block's stopping pass (an index into the pass ends)."""
    last = est.shape[0] - 1
    stop = np.full((by, bx), -1)
    below = np.zeros((by, bx), int)
    t2 = target * target
    for k in range(last + 1):
        decided = []
        for j in range(by):
            for i in range(bx):
                if stop[j, i] >= 0:
                    continue
                own = (est_min if rule == "min" else est)[k, j, i]
                ok = own <= t2
                if rule == "twice":
                    below[j, i] = below[j, i] + 1 if ok else 0
                    ok = below[j, i] >= 2
                elif rule in ("row", "3x3"):
                    rows = [0] if rule == "row" else [-1, 0, 1]
                    near = [(j + a, i + b) for a in rows for b in (-1, 0, 1)
                            if 0 <= j + a < by and 0 <= i + b < bx]
                    pooled = np.mean([est[stop[a, b] if stop[a, b] >= 0 else k, a, b]
                                      for a, b in near])
                    ok = ok and pooled <= t2
                if ok or k == last:
                    decided.append((j, i))
        for j, i in decided:
            stop[j, i] = k
    return stop


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene", nargs="?", default=os.path.join(nt.ROOT, "scenes", "translucent.json"))
    p.add_argument("--scale", type=float, default=0.1667)
    p.add_argument("--cap", type=int, default=2048)
    p.add_argument("--targets", type=float, nargs="+", default=[0.05, 0.07, 0.1])
    p.add_argument("--pairs", type=int, default=1, help="seed pairs (11, 12), (13, 14), ...")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--cost-spp", type=int, default=64)
    p.add_argument("--out", default=os.path.join(nt.ROOT, "build-noisebench"))
    args = p.parse_args()
    size = nt.scene_size(args.scene, args.scale)
    ends = pass_ends(args.cap)
    ref, ref_var = nt.reference(args, args.scene, size)
    costs = nt.block_costs(args, args.scene, size)
    by, bx = costs.shape
    pixels = nt.block_pixels(size)
    print(f"{os.path.basename(args.scene)} {size[0]}x{size[1]}, pass ends up to {ends[-1]}")
    print("| seeds | target | rule | mean spp | worst block | blocks above 1.1 E | at the cap | "
          "uniform spp at that worst block | time saved |")
    print("|---|---|---|---|---|---|---|---|---|")
    for pair in range(args.pairs):
        seed = 11 + 2 * pair
        a, b = films(args, args.scene, size, ends, seed)
        image = (a + b) / 2
        half_d = (a - b) / 2
        est = block_means((half_d / np.maximum(np.abs(image), FLOOR)) ** 2, by, bx)
        est_min = block_means((half_d / np.maximum(np.minimum(np.abs(a), np.abs(b)), FLOOR)) ** 2,
                              by, bx)
        uniform = [math.sqrt(max(float(nt.block_errors(image[k], ref, ref_var).max()), 0.0))
                   for k in range(len(ends))]
        for target in args.targets:
            for rule in RULES:
                stop = replay(rule, target, est, est_min, by, bx)
                final = np.zeros_like(image[0])
                n = np.zeros((by, bx))
                for j in range(by):
                    for i in range(bx):
                        sl = (slice(j * BLOCK, (j + 1) * BLOCK), slice(i * BLOCK, (i + 1) * BLOCK))
                        final[sl] = image[stop[j, i]][sl]
                        n[j, i] = ends[stop[j, i]]
                errs = np.sqrt(np.maximum(nt.block_errors(final, ref, ref_var), 0.0))
                worst = float(errs.max())
                # The uniform spp whose worst block is `worst`: log-log between pass ends, or the
                # 1/sqrt(n) law beyond them.
                k = next((k for k, u in enumerate(uniform) if u <= worst), None)
                if k is None or k == 0:
                    k0 = len(ends) - 1 if k is None else 0
                    n_uniform = ends[k0] * (uniform[k0] / worst) ** 2
                else:
                    x0, x1 = math.log(ends[k - 1]), math.log(ends[k])
                    y0, y1 = math.log(uniform[k - 1]), math.log(uniform[k])
                    n_uniform = math.exp(x0 + (math.log(worst) - y0) * (x1 - x0) / (y1 - y0))
                saved = n_uniform * float((costs * pixels).sum()) / float((costs * pixels * n).sum())
                print(f"| {seed}, {seed + 1} | {target} | {rule} | "
                      f"{float((pixels * n).sum() / pixels.sum()):.0f} | {worst:.3f} | "
                      f"{int((errs > 1.1 * target).sum())} | {int((n >= ends[-1]).sum())} | "
                      f"{n_uniform:.0f} | {saved:.2f}× |", flush=True)


if __name__ == "__main__":
    main()
