#!/usr/bin/python3
"""Segments, lookups and equal-time error of spectral vs. delta tracking (paper Sec. 4).

Usage: plot_segments.py DIR   (reads DIR/segments.csv, writes DIR/segments.png)
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(out):
    with open(f"{out}/segments.csv") as f:
        rows = list(csv.DictReader(f))
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    trackings = list(dict.fromkeys(r["tracking"] for r in rows))
    metrics = [("segments_relative_to_delta", "path segments (= lookups) per sample / delta"),
               ("segments_per_scatter_relative_to_delta", "path segments per scattering event / delta"),
               ("efficiency_relative_to_delta", "equal-time efficiency / delta\n(delta MSE x s / MSE x s)")]
    fig, axes = plt.subplots(1, len(metrics), figsize=(12, 3.6))
    width = 0.8 / len(trackings)
    for ax, (key, label) in zip(axes, metrics):
        for i, t in enumerate(trackings):
            values = [float(next(r[key] for r in rows if r["scene"] == s and r["tracking"] == t))
                      for s in scenes]
            ax.bar([j + i * width for j in range(len(scenes))], values, width, label=t)
        ax.axhline(1, color="black", lw=0.8)
        ax.set_xticks([j + width * (len(trackings) - 1) / 2 for j in range(len(scenes))])
        ax.set_xticklabels(scenes)
        ax.set_title(label, fontsize=9)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{out}/segments.png", dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
