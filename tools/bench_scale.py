#!/usr/bin/env python3
"""Render time against the number of objects or lights (docs/benchmarks.md, "Scenes at scale").

Writes scenes of N objects or lights at equal image coverage, renders each with one thread, and
prints per N the median over ROUNDS of the render's samples per second (from --stats), the
process's wall time and its peak memory. With two nimbus binaries the runs alternate, A B A B,
and the table gains the ratio A/B of samples per second.

  objects: N diffuse spheres (or free forms of four perturbations, --freeform) on a square grid
           over a floor, lit by a sun and a sky, 96 x 64 pixels, 4 spp.
  lights:  N sphere lights on a square grid over a diffuse floor, 64 x 64 pixels, 4 spp.
  puffs:   N index-matched spheres of one medium (constant density, or --cloud) on a square
           grid over a floor, each overlapping its neighbours, 96 x 64 pixels, 4 spp.

  --instances: the objects' or puffs' copies are one object's instances, from a .npy side file
               (docs/scene-format.md), as a million of them must be.

Usage: tools/bench_scale.py objects|lights|puffs N[,N...] ROUNDS NIMBUS [NIMBUS_B] [--freeform]
       [--cloud] [--instances]
"""
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time


def grid(n, half):
    """n points on a k x k grid over [-half, half]^2 (the first n of the k^2), and the spacing."""
    k = math.ceil(math.sqrt(n))
    step = 2 * half / k
    return [(-half + step * (i % k + 0.5), -half + step * (i // k + 0.5)) for i in range(n)], step


def write_placements(path, placements):
    """(scale, x, y, z) per copy as an (N, 3, 4) .npy of affine rows (docs/scene-format.md)."""
    import numpy  # only --instances needs it (Debian's python3-numpy)
    m = numpy.zeros((len(placements), 3, 4))
    p = numpy.array(placements, dtype=float).reshape(-1, 4)
    m[:, 0, 0] = m[:, 1, 1] = m[:, 2, 2] = p[:, 0]
    m[:, :, 3] = p[:, 1:]
    numpy.save(path, m)


def objects_scene(n, freeform, instances=None):
    points, step = grid(n, 4.0)
    r = 0.4 * step
    shapes = {"floor": {"type": "box", "min": [-6, -1, -6], "max": [6, 0, 6]}}
    objects = [{"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}}]
    if freeform:
        shapes["rock"] = {"type": "freeform", "base": {"type": "sphere", "radius": 1},
                          "perturbations": [
                              {"shape": {"type": "sphere", "center": c, "radius": 0.5},
                               "weight": w}
                              for c, w in (([0.8, 0.3, 0], 2), ([-0.5, 0.6, 0.4], -3),
                                           ([0.1, -0.7, 0.6], 2), ([0, 0.2, -0.9], -2))]}
    if instances:
        # One object whose copies sit in a .npy side file: the shape is compiled once.
        if not freeform:
            shapes["rock"] = {"type": "sphere", "radius": 1}
        write_placements(instances, [(r, x, r, z) for x, z in points])
        objects.append({"shape": "rock", "surface": {"type": "diffuse", "albedo": 0.7},
                        "instances": {"file": os.path.basename(instances)}})
        points = []
    for x, z in points:
        if freeform:
            shape = {"type": "union", "transform": [{"scale": r}, {"translate": [x, r, z]}],
                     "shapes": ["rock"]}
        else:
            shape = {"type": "sphere", "center": [x, r, z], "radius": r}
        objects.append({"shape": shape, "surface": {"type": "diffuse", "albedo": 0.7}})
    return {"film": {"width": 96, "height": 64},
            "camera": {"from": [0, 7, 9], "to": [0, 0, 0], "fov": 50},
            "integrator": {"spp": 4, "max_depth": 4},
            "lights": [{"type": "directional", "direction": [-0.3, -1, -0.4], "irradiance": 2},
                       {"type": "environment", "radiance": 0.3}],
            "shapes": shapes, "objects": objects}


def lights_scene(n):
    points, step = grid(n, 4.0)
    r = 0.2 * step
    lights = [{"type": "sphere", "center": [x, 0.5 + r, z], "radius": r, "radiance": 1 / (r * r)}
              for x, z in points]
    return {"film": {"width": 64, "height": 64},
            "camera": {"from": [0, 7, 9], "to": [0, 0, 0], "fov": 50},
            "integrator": {"spp": 4, "max_depth": 4},
            "lights": lights,
            "shapes": {"floor": {"type": "box", "min": [-6, -1, -6], "max": [6, 0, 6]}},
            "objects": [{"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}}]}


def puffs_scene(n, cloud, instances=None):
    points, step = grid(n, 4.0)
    r = 0.7 * step  # a puff reaches into its neighbours
    medium = {"sigma_a": 0.1 / r, "sigma_s": 2 / r, "phase": {"type": "hg", "g": 0.6}}
    if cloud:
        medium["density"] = {"type": "cloud", "frequency": 1 / r}
    objects = [{"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}}]
    if instances:
        write_placements(instances, [(r, x, r, z) for x, z in points])
        objects.append({"shape": {"type": "sphere", "radius": 1}, "surface": {"type": "none"},
                        "medium": "puff", "instances": {"file": os.path.basename(instances)}})
    else:
        objects += [{"shape": {"type": "sphere", "center": [x, r, z], "radius": r},
                     "surface": {"type": "none"}, "medium": "puff"} for x, z in points]
    return {"film": {"width": 96, "height": 64},
            "camera": {"from": [0, 7, 9], "to": [0, 0, 0], "fov": 50},
            "integrator": {"spp": 4, "max_depth": 4},
            "lights": [{"type": "directional", "direction": [-0.3, -1, -0.4], "irradiance": 2},
                       {"type": "environment", "radiance": 0.3}],
            "shapes": {"floor": {"type": "box", "min": [-6, -1, -6], "max": [6, 0, 6]}},
            "media": {"puff": medium}, "objects": objects}


def run(nimbus, scene, out):
    """Samples per second, wall seconds and peak resident MiB of one render."""
    stats = os.path.join(out, "stats.json")
    start = time.monotonic()
    child = subprocess.Popen([nimbus, "render", scene, "-o", os.path.join(out, "image.exr"),
                              "-q", "--threads", "1", "--stats", stats])
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.monotonic() - start
    if status != 0:
        sys.exit(f"{nimbus} failed on {scene}")
    with open(stats) as f:
        s = json.load(f)
    return s["samples_per_second"], wall, usage.ru_maxrss / 1024


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    freeform, cloud = "--freeform" in sys.argv, "--cloud" in sys.argv
    copies = "--instances" in sys.argv
    kind, counts, rounds = args[0], [int(n) for n in args[1].split(",")], int(args[2])
    binaries = args[3:]
    out = tempfile.mkdtemp()
    variant = " (free forms)" if freeform else " (cloud density)" if cloud else ""
    print(f"{kind}{variant}: median of {rounds}, one thread")
    header = "| N | " + " | ".join(f"samples/s {'AB'[i]} | wall s {'AB'[i]} | peak MiB {'AB'[i]}"
                                    for i in range(len(binaries)))
    print(header + (" | A/B samples/s |" if len(binaries) == 2 else " |"))
    for n in counts:
        scene = os.path.join(out, f"{kind}_{n}.json")
        npy = os.path.join(out, f"{kind}_{n}.npy") if copies else None
        with open(scene, "w") as f:
            json.dump({"objects": lambda: objects_scene(n, freeform, npy),
                       "lights": lambda: lights_scene(n),
                       "puffs": lambda: puffs_scene(n, cloud, npy)}[kind](), f)
        results = [[] for _ in binaries]
        for _ in range(rounds):
            for i, b in enumerate(binaries):
                results[i].append(run(b, scene, out))
        cells, rates = [], []
        for r in results:
            rate = statistics.median(x[0] for x in r)
            rates.append(rate)
            cells.append(f"{rate:.3g} | {statistics.median(x[1] for x in r):.2f} | "
                         f"{statistics.median(x[2] for x in r):.0f}")
        ratio = f" {rates[0] / rates[1]:.2f} |" if len(binaries) == 2 else ""
        print(f"| {n} | " + " | ".join(cells) + " |" + ratio, flush=True)


main()
