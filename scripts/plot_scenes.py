#!/usr/bin/env python3
"""scene_benchmark CSVs: Es and Ea of every registration per scene type, motion and start bounds
(log scale, the success limits drawn), and a markdown table of the groups.

usage: /usr/bin/python3 scripts/plot_scenes.py OUT.png SCENES.csv [LABEL]
       /usr/bin/python3 scripts/plot_scenes.py --table SCENES.csv [SCENES.csv ...]
"""
import csv
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def quantile(values, q):
    """The value at index floor(q n) of the sorted values, as core/metrics.h quantile()."""
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))] if v else float("nan")


def groups(path):
    out = OrderedDict()
    with open(path) as fh:
        for r in csv.DictReader(fh):
            out.setdefault((r["scene"], r["motion"], r["bounds"]), []).append(r)
    return OrderedDict(sorted(out.items()))


def table(paths):
    print("| run | scene | motion | starts | success | Es median / p95 / max [m] | "
          "Ea median / p95 / max [deg] | median s | accepted | false accepts | false rejects |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for path in paths:
        label = path.rsplit("/", 1)[-1].replace(".csv", "")
        for (scene, motion, bounds), rows in groups(path).items():
            es = [float(r["Es_m"]) for r in rows]
            ea = [float(r["Ea_deg"]) for r in rows]
            t = [float(r["time_s"]) for r in rows]
            ok = [r["success"] == "1" for r in rows]
            acc = [r["gate"] == "accepted" for r in rows]
            fa = sum(a and not s for a, s in zip(acc, ok))
            fr = sum(s and not a for a, s in zip(acc, ok))
            print("| %s | %s | %s | %s | %d/%d | %.3f / %.3f / %.3f | %.2f / %.2f / %.2f | %.3f | "
                  "%d | %d | %d |" % (
                      label, scene, motion, bounds, sum(ok), len(rows), quantile(es, 0.5),
                      quantile(es, 0.95), max(es), quantile(ea, 0.5), quantile(ea, 0.95), max(ea),
                      quantile(t, 0.5), sum(acc), fa, fr))


def plot(out, path, label):
    g = groups(path)
    fig, axes = plt.subplots(2, 1, figsize=(11, 7), sharex=True)
    names = []
    for i, ((scene, motion, bounds), rows) in enumerate(g.items()):
        names.append("%s\n%s\n%s" % (scene, motion, bounds))
        for ax, key, limit in ((axes[0], "Es_m", 0.10), (axes[1], "Ea_deg", 1.0)):
            vals = [max(float(r[key]), 1e-4) for r in rows]
            colors = ["tab:red" if r["gate"] == "accepted" and r["success"] != "1" else
                      ("tab:orange" if r["gate"] != "accepted" else "tab:blue") for r in rows]
            xs = [i + (k % 9 - 4) * 0.04 for k in range(len(vals))]
            ax.scatter(xs, vals, s=6, c=colors)
            ax.axhline(limit, color="gray", lw=0.8, ls="--")
    axes[0].set_yscale("log")
    axes[1].set_yscale("log")
    axes[0].set_ylabel("Es [m]")
    axes[1].set_ylabel("Ea [deg]")
    axes[1].set_xticks(range(len(names)))
    axes[1].set_xticklabels(names, fontsize=7)
    axes[0].set_title("%s: every registration (blue accepted, orange rejected, red accepted but "
                      "wrong); dashed = success limit" % label, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "--table":
        table(sys.argv[2:])
    elif len(sys.argv) in (3, 4):
        plot(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else sys.argv[2])
    else:
        sys.exit(__doc__)
