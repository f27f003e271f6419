#!/usr/bin/env python3
"""Renders scenes/demo.json at 4, 16 and 64 samples per pixel through the Python module and saves
a figure of the three images with their noise against a 256-spp render (docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/spp_figure.py [OUT.png]
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # a file, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import nimbus  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
scene = nimbus.load_file(os.path.join(here, "..", "..", "scenes", "demo.json"),
                         {"film.width": 96, "film.height": 72})
reference = nimbus.render(scene, spp=256, seed=1)
counts = [4, 16, 64]
figure, axes = plt.subplots(1, len(counts), figsize=(3.2 * len(counts), 2.8))
for ax, spp in zip(axes, counts):
    image = nimbus.render(scene, spp=spp)
    rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
    ax.imshow(np.clip(image, 0, 1) ** (1 / 2.2))  # a display gamma over linear sRGB
    ax.set_title(f"{spp} spp, RMSE {rmse:.3f}")
    ax.axis("off")
figure.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "spp_figure.png"
figure.savefig(out, dpi=100)
print(out)
