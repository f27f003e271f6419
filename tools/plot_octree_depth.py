#!/usr/bin/python3
"""Build time, memory and tracking cost against octree depth, like the paper's Fig. 7.

Usage: plot_octree_depth.py DIR   (reads DIR/octree_depth.csv, writes DIR/octree_depth.png)
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out):
    with open(f"{out}/octree_depth.csv") as f:
        rows = list(csv.DictReader(f))
    depth = [int(r["depth"]) for r in rows]

    def col(name):
        return [float(r[name]) for r in rows]

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    ax = axes[0]
    ax.plot(depth, col("render_seconds"), "o-", label="render")
    ax.plot(depth, col("build_seconds"), "s-", label="octree build")
    ax.set_ylabel("seconds")
    ax.set_title("time")
    ax.legend()
    ax = axes[1]
    ax.plot(depth, col("lookups_per_sample"), "o-", label="density lookups")
    ax.plot(depth, col("segments_per_sample"), "s-", label="majorant segments")
    ax.set_yscale("log")
    ax.set_ylabel("per pixel sample")
    ax.set_title("tracking work")
    ax.legend()
    ax = axes[2]
    ax.plot(depth, [b / 2**20 for b in col("bytes")], "o-", label="memory (MiB)")
    ax.plot(depth, [n / 1000 for n in col("nodes")], "s-", label="nodes (thousands)")
    ax.set_title("octree size")
    ax.legend()
    for ax in axes:
        ax.set_xlabel("octree depth")
        ax.set_xticks(depth)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out}/octree_depth.png", dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
