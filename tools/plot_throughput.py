#!/usr/bin/python3
"""Figs. 4-5: path throughput against distance, max rule vs. history-aware rule.

Usage: plot_throughput.py DIR   (reads DIR/throughput.csv, writes DIR/throughput_<medium>.png)
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

COLOURS = {"r": "tab:red", "g": "tab:green", "b": "tab:blue"}
TITLES = {"max": "max rule (eq. 6-9, Fig. 4)", "history": "history-aware average (eq. 10-13, Fig. 5)"}


def main(out):
    rows = defaultdict(list)
    with open(f"{out}/throughput.csv") as f:
        for r in csv.DictReader(f):
            rows[(r["medium"], r["rule"], r["channel"])].append(r)
    for medium in sorted({k[0] for k in rows}):
        fig, axes = plt.subplots(3, 2, figsize=(10, 8), sharex=True, sharey=True)
        for col, rule in enumerate(["max", "history"]):
            for row, ch in enumerate(["r", "g", "b"]):
                ax = axes[row][col]
                colour = COLOURS[ch]
                data = rows[(medium, rule, ch)]
                d = [float(r["distance"]) for r in data]
                ax.fill_between(d, [float(r["q05"]) for r in data],
                                [float(r["q95"]) for r in data], color=colour, alpha=0.15,
                                label="5-95 %")
                ax.plot(d, [float(r["mean"]) for r in data], color=colour, label="mean")
                ax.plot(d, [float(r["q50"]) for r in data], color=colour, ls="--", label="median")
                ax.plot(d, [float(r["max"]) for r in data], color=colour, ls=":", label="largest")
                avg = rows[(medium, rule, "avg")]
                ax.plot(d, [float(r["mean"]) for r in avg], color="black", lw=0.8,
                        label="mean of channel average")
                ax.set_yscale("log")
                ax.set_ylim(1e-4, 1e4)
                ax.grid(alpha=0.3)
                if row == 0:
                    ax.set_title(TITLES[rule])
                if col == 0:
                    ax.set_ylabel(f"{ch.upper()} throughput")
                if row == 2:
                    ax.set_xlabel("distance travelled")
        axes[0][1].legend(fontsize=7, loc="upper left")
        fig.suptitle(f"Spectral tracking throughput, {medium} medium, albedo 1, "
                     "sigma_s = (1, 5, 10) (zeros not shown)")
        fig.tight_layout()
        fig.savefig(f"{out}/throughput_{medium}.png", dpi=72)
        plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
