#!/usr/bin/env python3
"""Writes scenes/lanterns.json: lanterns in fog, a scene at scale (docs/benchmarks.md, "Scenes at
scale"). Hundreds of small sphere lights hang over a meadow of free-form rocks, in a ground fog
made of a thousand overlapping index-matched puffs whose media add where they meet. Fixed seed:
the same file every time.

Usage: tools/make_lanterns.py [OUT]   (default: scenes/lanterns.json)
"""
import json
import random
import sys

LANTERNS = 400
PUFFS = 1200
ROCKS = 24


def r3(v):
    return [round(x, 4) for x in v]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/lanterns.json"
    rng = random.Random(7)
    lights = [{"type": "environment", "radiance": [0.012, 0.016, 0.03]}]
    for _ in range(LANTERNS):
        x, z = rng.uniform(-11, 11), rng.uniform(-16, 3)
        warm = rng.uniform(0.8, 1.2)
        lights.append({"type": "sphere", "center": r3([x, rng.uniform(0.3, 2.0), z]),
                       "radius": 0.08, "radiance": r3([30 * warm, 16 * warm, 5 * warm])})
    shapes = {"ground": {"type": "box", "min": [-30, -1, -40], "max": [30, 0, 8]}}
    objects = [{"shape": "ground", "surface": {"type": "diffuse", "albedo": [0.35, 0.33, 0.3]}}]
    for i in range(ROCKS):
        c = [rng.uniform(-6, 6), 0.0, rng.uniform(-8, 3)]
        s = rng.uniform(0.3, 0.7)
        bumps = [{"shape": {"type": "ellipsoid",
                            "center": r3([c[0] + s * rng.uniform(-0.9, 0.9), s * rng.uniform(0, 0.8),
                                          c[2] + s * rng.uniform(-0.9, 0.9)]),
                            "radii": r3([s * rng.uniform(0.4, 0.7)] * 3)},
                  "weight": round(rng.uniform(0.3, 0.6), 3)} for _ in range(4)]
        shapes[f"rock{i}"] = {"type": "freeform",
                              "base": {"type": "ellipsoid", "center": r3(c),
                                       "radii": r3([s, 0.6 * s, s * rng.uniform(0.8, 1.2)])},
                              "perturbations": bumps}
        objects.append({"shape": f"rock{i}",
                        "surface": {"type": "diffuse", "albedo": [0.3, 0.29, 0.27]}})
    for i in range(PUFFS):
        shapes[f"puff{i}"] = {"type": "sphere",
                              "center": r3([rng.uniform(-14, 14), rng.uniform(-0.2, 1.0),
                                            rng.uniform(-22, 5)]),
                              "radius": round(rng.uniform(0.8, 1.8), 3)}
        objects.append({"shape": f"puff{i}", "surface": {"type": "none"}, "medium": "fog"})
    scene = {
        "film": {"width": 640, "height": 320},
        "camera": {"from": [0, 1.3, 7], "to": [0, 1.0, -4], "fov": 50},
        "integrator": {"spp": 64, "seed": 0, "max_depth": 8},
        "lights": lights,
        "media": {"fog": {"sigma_s": 0.015, "sigma_a": 0.0015, "phase": {"type": "hg", "g": 0.5}}},
        "shapes": shapes,
        "objects": objects,
    }
    with open(out, "w") as f:
        json.dump(scene, f, separators=(",", ":"))
        f.write("\n")


if __name__ == "__main__":
    main()
