#!/usr/bin/env python3
"""Renders scenes/demo.json at 4, 16 and 64 samples per pixel through the Python module and saves
a figure of the three images with their noise against a 256-spp render (docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/spp_figure.py [OUT.png]
        [--size 96 72] [--reference-spp 256]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")  # a file, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nimbus  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("out", nargs="?", default="spp_figure.png")
parser.add_argument("--size", type=int, nargs=2, default=(96, 72), metavar=("WIDTH", "HEIGHT"))
parser.add_argument("--reference-spp", type=int, default=256)
args = parser.parse_args()

here = os.path.dirname(os.path.abspath(__file__))
scene = nimbus.load_file(os.path.join(here, "..", "..", "scenes", "demo.json"),
                         {"film.width": args.size[0], "film.height": args.size[1]})
reference = nimbus.render(scene, spp=args.reference_spp, seed=1)
counts = [4, 16, 64]
figure, axes = plt.subplots(1, len(counts), figsize=(3.2 * len(counts), 2.8))
for ax, spp in zip(axes, counts):
    image = nimbus.render(scene, spp=spp)
    rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
    ax.imshow(np.clip(image, 0, 1) ** (1 / 2.2))  # a display gamma over linear sRGB
    ax.set_title(f"{spp} spp, RMSE {rmse:.3f}")
    ax.axis("off")
figure.tight_layout()
figure.savefig(args.out, dpi=100)
print(args.out)
