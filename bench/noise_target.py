#!/usr/bin/env python3
"""Time to a noise target against uniform sampling (issue 45; docs/benchmarks.md, "Noise target").

For each scene, at a fraction of its size:
  1. a reference: two uniform renders of REF_SPP/2 at seeds 977 and 978; their mean is the
     reference, a quarter of their squared difference each pixel's variance of it;
  2. the render to the target: `--noise-target E --spp CAP` at seed 1, its time and its
     worst-block error;
  3. uniform renders at seed 1: the spp with the same worst-block error, found from the one at
     the noise target's mean spp (equal samples, about equal time) by the error's 1/sqrt(spp)
     law, then rendered and measured; the search repeats once if that misses by over 10 %.
  4. the ceiling: the time saved by giving each 8x8 block exactly the samples that take it to
     the target render's worst block (from its error in the matched uniform render), each
     sample at its block's cost, measured by rendering every block alone (render_into's
     pixels, one thread, COST_SPP); --no-oracle skips it.
Times are CPU seconds (user + system) of the process less those of a render of 1 spp (loading,
octrees, writing), so that a shared machine's load stretches them less than the wall clock.
A block's error is that of the noise target's rule, measured against the reference: over the
8x8 block's pixels and channels, the root mean square of (image - reference) / max(reference,
2^-8), less the reference's own expected error (its variance, per pixel). The rMSE is the mean
over all pixels and channels of the same relative squared error, less the reference's.

  PYTHONPATH=build/python /usr/bin/python3 bench/noise_target.py [--nimbus build/nimbus]
      [--scale 0.25] [--target 0.05] [--cap 4096] [--min-spp 16] [--ref-spp 1024] [--threads 2]
      [--out build-noisebench] [--cost-spp 64] [--no-oracle] [SCENE...]

SCENE: files (default scenes/demo.json scenes/translucent.json scenes/cloud.json
scenes/lanterns.json). References are cached in OUT/refs by scene, size and REF_SPP.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BLOCK = 8
FLOOR = 2.0 ** -8


def render(args, scene, size, out, spp, seed, extra=()):
    """Renders to out (EXR); returns (image array, --stats dict with "cpu_seconds": the process's
    user + system time, which a loaded machine stretches less than the wall clock)."""
    stats = out + ".json"
    cmd = [args.nimbus, "render", scene, "-q", "-o", out, "--stats", stats, "--spp", str(spp),
           "--seed", str(seed), "--threads", str(args.threads),
           "--set", f"film.width={size[0]}", "--set", f"film.height={size[1]}", *extra]
    proc = subprocess.Popen(cmd)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {proc.returncode}")
    import nimbus
    with open(stats) as f:
        st = json.load(f)
    st["cpu_seconds"] = usage.ru_utime + usage.ru_stime
    return np.asarray(nimbus.read_exr(out), dtype=np.float64), st


def scene_size(scene, scale):
    """The scene file's film size times `scale`, at least a block each way."""
    with open(scene) as f:
        film = json.load(f).get("film", {})
    return (max(BLOCK, round(film.get("width", 640) * scale)),
            max(BLOCK, round(film.get("height", 480) * scale)))


def block_pixels(size):
    """The pixels of each 8x8 block of an image of `size`, cut at its edges, as (blocks down,
    blocks across)."""
    return np.array([[min(BLOCK, size[0] - x) * min(BLOCK, size[1] - y)
                      for x in range(0, size[0], BLOCK)] for y in range(0, size[1], BLOCK)])


def reference(args, scene, size):
    name = os.path.splitext(os.path.basename(scene))[0]
    base = os.path.join(args.out, "refs", f"{name}_{size[0]}x{size[1]}_{args.ref_spp}")
    os.makedirs(os.path.dirname(base), exist_ok=True)
    if os.path.exists(base + ".npz"):
        z = np.load(base + ".npz")
        return z["mean"], z["var"]
    a, _ = render(args, scene, size, base + "_a.exr", args.ref_spp // 2, 977)
    b, _ = render(args, scene, size, base + "_b.exr", args.ref_spp // 2, 978)
    mean, var = (a + b) / 2, (a - b) ** 2 / 4
    np.savez(base + ".npz", mean=mean, var=var)
    return mean, var


def relative_sq(image, ref, ref_var):
    """Each pixel's and channel's squared relative error, less the reference's own."""
    return ((image - ref) ** 2 - ref_var) / np.maximum(np.abs(ref), FLOOR) ** 2


def block_errors(image, ref, ref_var):
    """Each 8x8 block's squared relative error (the rule's measure against the reference), as an
    array of (blocks down, blocks across)."""
    sq = relative_sq(image, ref, ref_var)
    h, w = sq.shape[:2]
    return np.array([[float(sq[y:y + BLOCK, x:x + BLOCK].mean()) for x in range(0, w, BLOCK)]
                     for y in range(0, h, BLOCK)])


def errors(image, ref, ref_var):
    """(worst block's relative error, relative MSE), each less the reference's own."""
    worst = max(float(block_errors(image, ref, ref_var).max()), 0.0)
    return math.sqrt(worst), float(relative_sq(image, ref, ref_var).mean())


def block_costs(args, scene, size):
    """CPU seconds per sample of each 8x8 block: each block rendered alone (render_into with its
    pixels) at COST_SPP on one thread, as (blocks down, blocks across) per pixel-sample."""
    import time

    import nimbus
    sc = nimbus.load_file(scene, {"film.width": size[0], "film.height": size[1]})
    film = nimbus.Film(sc)
    nimbus.render_into(sc, film, samples=(0, 1), seed=5, threads=1, pixels=(0, 0, BLOCK, BLOCK))
    costs = []
    for y in range(0, size[1], BLOCK):
        row = []
        for x in range(0, size[0], BLOCK):
            px = (x, y, min(x + BLOCK, size[0]), min(y + BLOCK, size[1]))
            f = nimbus.Film(sc)
            t0 = time.process_time()
            nimbus.render_into(sc, f, samples=(0, args.cost_spp), seed=5, threads=1, pixels=px)
            row.append((time.process_time() - t0) / (args.cost_spp * (px[2] - px[0]) *
                                                        (px[3] - px[1])))
        costs.append(row)
    return np.array(costs)


def oracle(args, scene, size, uniform, uniform_spp, worst, ref, ref_var):
    """The most that any allocation of samples per block can save against uniform sampling, at
    the render to the target's worst block W: each block given exactly the samples that take it
    to W, n_b = N (e_b / W)^2 from a uniform render of N spp (its error e_b; the 1/sqrt(n) law,
    which RQMC can beat, so this ceiling is if anything high), each sample at its block's
    measured cost. Returns (ceiling, its mean spp, its cost per sample over uniform's)."""
    e2 = np.maximum(block_errors(uniform, ref, ref_var), 0.0)
    n = np.maximum(1.0, uniform_spp * e2 / worst ** 2)
    n_max = float(n.max())
    c = block_costs(args, scene, size)
    pixels = block_pixels(size)
    t_uniform = n_max * float((c * pixels).sum())
    t_oracle = float((c * pixels * n).sum())
    cost_ratio = float((c * pixels * n).sum() / (pixels * n).sum()) / float(
        (c * pixels).sum() / pixels.sum())
    return t_uniform / t_oracle, float((pixels * n).sum() / pixels.sum()), cost_ratio


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="*", default=[os.path.join(ROOT, "scenes", s + ".json") for s in
                                                 ("demo", "translucent", "cloud", "lanterns")])
    p.add_argument("--nimbus", default=os.path.join(ROOT, "build", "nimbus"))
    p.add_argument("--scale", type=float, default=0.25)
    p.add_argument("--target", type=float, default=0.05)
    p.add_argument("--cap", type=int, default=4096)
    p.add_argument("--min-spp", type=int, default=16, help="--noise-min-spp")
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--out", default=os.path.join(ROOT, "build-noisebench"))
    p.add_argument("--cost-spp", type=int, default=64,
                   help="samples per pixel of each block rendered alone to measure its cost")
    p.add_argument("--no-oracle", action="store_true", help="skip the per-block ceiling")
    args = p.parse_args()
    try:
        import nimbus  # noqa: F401  (reads the EXRs)
    except ImportError:
        sys.exit("bench/noise_target.py: needs the nimbus module: PYTHONPATH=build/python")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for scene in args.scenes:
        size = scene_size(scene, args.scale)
        name = os.path.splitext(os.path.basename(scene))[0]
        ref, ref_var = reference(args, scene, size)
        _, setup = render(args, scene, size, os.path.join(args.out, name + "_setup.exr"), 1, 1)

        def seconds(st):
            return st["cpu_seconds"] - setup["cpu_seconds"]
        adaptive, a_stats = render(args, scene, size, os.path.join(args.out, name + "_target.exr"),
                                   args.cap, 1, ("--noise-target", str(args.target),
                                                           "--noise-min-spp", str(args.min_spp)))
        a_worst, a_rmse = errors(adaptive, ref, ref_var)
        mean_spp = a_stats["noise_target"]["mean_spp"]
        # Uniform at equal samples, then at the spp its worst block's error says would match.
        spp = max(1, round(mean_spp))
        tried = {}
        for _ in range(3):
            if spp in tried:
                break
            img, st = render(args, scene, size, os.path.join(args.out, f"{name}_uniform.exr"), spp, 1)
            tried[spp] = (errors(img, ref, ref_var), seconds(st), img)
            (worst, _), _, _ = tried[spp]
            if abs(worst / a_worst - 1) < 0.1 and spp != max(1, round(mean_spp)):
                break
            spp = max(1, round(spp * (worst / a_worst) ** 2))
        equal = tried[max(1, round(mean_spp))]
        match = min(tried.items(), key=lambda kv: abs(kv[1][0][0] / a_worst - 1))
        ceiling = (None, None, None)
        if not args.no_oracle:
            ceiling = oracle(args, scene, size, match[1][2], match[0], a_worst, ref, ref_var)
        row = {
            "scene": name, "size": f"{size[0]}x{size[1]}", "target": args.target,
            "target_seconds": seconds(a_stats), "target_mean_spp": mean_spp,
            "target_max_spp": a_stats["noise_target"]["max_spp"],
            "target_worst_block": a_worst, "target_rmse": a_rmse,
            "equal_spp": max(1, round(mean_spp)), "equal_seconds": equal[1],
            "equal_worst_block": equal[0][0], "equal_rmse": equal[0][1],
            "uniform_spp": match[0], "uniform_seconds": match[1][1],
            "uniform_worst_block": match[1][0][0],
            "speedup": match[1][1] / seconds(a_stats),
            "ceiling": ceiling[0], "ceiling_mean_spp": ceiling[1], "ceiling_cost_ratio": ceiling[2],
        }
        rows.append(row)
        print(json.dumps(row), flush=True)
    print()
    print("| scene | size | target: time, mean / max spp, worst block, rMSE | uniform at equal "
          "samples: worst block, rMSE | uniform at the same worst block: spp, time | time saved | "
          "ceiling: time saved, mean spp, cost per sample ÷ uniform's |")
    print("(times: CPU seconds less a 1-spp render's)")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['scene']} | {r['size']} | {r['target_seconds']:.1f} s, {r['target_mean_spp']:.0f}"
              f" / {r['target_max_spp']}, {r['target_worst_block']:.3f}, {r['target_rmse']:.2e} | "
              f"{r['equal_worst_block']:.3f}, {r['equal_rmse']:.2e} | {r['uniform_spp']}, "
              f"{r['uniform_seconds']:.1f} s (worst block {r['uniform_worst_block']:.3f}) | "
              f"{r['speedup']:.1f}x | " + ("—" if r["ceiling"] is None else
                                             f"{r['ceiling']:.2f}x, {r['ceiling_mean_spp']:.0f}, "
                                             f"{r['ceiling_cost_ratio']:.2f}") + " |")


if __name__ == "__main__":
    main()
