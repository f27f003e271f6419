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

COLOURS = {"r": "tab:red", "g": "tab:green", "b": "tab:blue", "avg": "black"}
TITLES = {"max": "max rule (eq. 6-9, Fig. 4)", "history": "history-aware average (eq. 10-13, Fig. 5)"}


def main(out):
    rows = defaultdict(list)
    with open(f"{out}/throughput.csv") as f:
        for r in csv.DictReader(f):
            rows[(r["medium"], r["rule"], r["channel"])].append(r)
    for medium in sorted({k[0] for k in rows}):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
        for ax, rule in zip(axes, ["max", "history"]):
            for ch, colour in COLOURS.items():
                data = rows.get((medium, rule, ch))
                if not data:
                    continue
                d = [float(r["distance"]) for r in data]
                mean = [float(r["mean"]) for r in data]
                lo = [float(r["q05"]) for r in data]
                hi = [float(r["q95"]) for r in data]
                sd = [float(r["std"]) for r in data]
                label = "channel average" if ch == "avg" else ch.upper()
                ax.plot(d, mean, color=colour, label=f"{label} mean")
                if ch != "avg":
                    ax.plot(d, [m + s for m, s in zip(mean, sd)], color=colour, ls=":", lw=1)
                    ax.fill_between(d, lo, hi, color=colour, alpha=0.12)
            ax.set_title(TITLES[rule])
            ax.set_xlabel("distance travelled")
            ax.set_yscale("symlog", linthresh=1)
            ax.grid(alpha=0.3)
        axes[0].set_ylabel("path throughput (mean; dotted mean+std; band 5-95 %)")
        axes[1].legend(fontsize=8)
        fig.suptitle(f"Spectral tracking throughput, {medium} medium, albedo 1, sigma_s = (1, 5, 10)")
        fig.tight_layout()
        fig.savefig(f"{out}/throughput_{medium}.png", dpi=80)
        plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
