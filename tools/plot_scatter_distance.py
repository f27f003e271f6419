#!/usr/bin/python3
"""Fig. 6: density of the distances between scattering events, both rules vs. the closed form.

Usage: plot_scatter_distance.py DIR   (reads DIR/scatter_distance.csv, writes DIR/scatter_distance.png)
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

COLOURS = {"r": "tab:red", "g": "tab:green", "b": "tab:blue"}


def main(out):
    rows = defaultdict(list)
    with open(f"{out}/scatter_distance.csv") as f:
        for r in csv.DictReader(f):
            rows[r["rule"]].append(r)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, rule in zip(axes, ["max", "history"]):
        data = rows[rule]
        x = [(float(r["distance_lo"]) + float(r["distance_hi"])) / 2 for r in data]
        ax.step(x, [float(r["sampled_between"]) for r in data], where="mid", color="black",
                label="sampled (between events)")
        ax.step(x, [float(r["sampled_first"]) for r in data], where="mid", color="grey", ls="--",
                label="sampled (first event)")
        for ch, colour in COLOURS.items():
            ax.plot(x, [float(r[f"weighted_{ch}"]) for r in data], ".", ms=3, color=colour,
                    label=f"weighted by {ch.upper()} throughput")
            ax.plot(x, [float(r[f"analytic_{ch}"]) for r in data], color=colour, lw=1,
                    label=f"sigma_s exp(-sigma_s t), {ch.upper()}")
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 20)
        ax.set_xlim(0, 3)
        ax.set_title(f"{rule} rule")
        ax.set_xlabel("distance between scattering events")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("density")
    axes[1].legend(fontsize=7)
    fig.suptitle("Scattering distances, albedo 1, sigma_s = (1, 5, 10)")
    fig.tight_layout()
    fig.savefig(f"{out}/scatter_distance.png", dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
