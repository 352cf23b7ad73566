#!/usr/bin/env python3
"""Plots median time and median Es per method and pair from benchmark CSVs.

usage: /usr/bin/python3 scripts/plot_benchmark.py OUT.png FILE.csv [FILE.csv ...]
"""
import csv
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    out, files = sys.argv[1], sys.argv[2:]
    rows = []
    for f in files:
        with open(f) as fh:
            rows += list(csv.DictReader(fh))
    pairs = sorted({r["pair"] for r in rows})
    methods = list(dict.fromkeys(r["method"] for r in rows))
    fig, axes = plt.subplots(1, 2, figsize=(14, 5))
    width = 0.8 / len(pairs)
    for k, pair in enumerate(pairs):
        t, es = [], []
        for m in methods:
            sel = [r for r in rows if r["pair"] == pair and r["method"] == m]
            t.append(statistics.median(float(r["time_s"]) for r in sel) if sel else 0)
            es.append(statistics.median(float(r["Es_m"]) for r in sel) if sel else 0)
        xs = [i + k * width for i in range(len(methods))]
        axes[0].bar(xs, t, width, label=pair)
        axes[1].bar(xs, es, width, label=pair)
    for ax, title in ((axes[0], "median time per registration [s] (log)"),
                      (axes[1], "median Es [m] (log)")):
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(methods))])
        ax.set_xticklabels(methods, rotation=45, ha="right", fontsize=8)
        ax.set_yscale("log")
        ax.set_title(title)
    axes[1].axhline(0.10, color="k", lw=0.8, ls="--")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
