#!/usr/bin/env python3
"""scene_benchmark CSVs: Es and Ea of every registration per scene type, motion and start bounds
(log scale, the success limits drawn), and a markdown table of the groups.

usage: /usr/bin/python3 scripts/plot_scenes.py OUT.png SCENES.csv [LABEL]
       /usr/bin/python3 scripts/plot_scenes.py --table SCENES.csv [SCENES.csv ...]
       /usr/bin/python3 scripts/plot_scenes.py --calibrate SCENES.csv [SCENES.csv ...]
       /usr/bin/python3 scripts/plot_scenes.py --targets SCENES.csv [SCENES.csv ...]

--calibrate: for the accepted successful registrations with a covariance, the fraction of each
axis's errors beyond 3 predicted standard deviations, and the smallest factor on the
covariance (covariance_scale, relative to the run's) that brings every axis to <= 1 %.

--targets: the scene benchmark's targets per scene type, the CSVs pooled: successes from the big starts
(>= 99.5 %) and from all; median / p95 Es and Ea of the accepted results (<= 2 cm, 0.1 deg /
5 cm, 0.3 deg); false accepts (0); false rejects as a share of the right results (<= 1 %); the
accepted results' worst axis beyond 3 predicted sd (<= 1 %); and the targets each type misses.
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


AXES = ("x", "y", "z", "rx", "ry", "rz")
ERR = ("ex_m", "ey_m", "ez_m", "erx_rad", "ery_rad", "erz_rad")
SIG = ("sx_m", "sy_m", "sz_m", "srx_rad", "sry_rad", "srz_rad")


def calibrate(paths):
    z = [[] for _ in AXES]  # |error| / sigma per axis
    for path in paths:
        with open(path) as fh:
            for r in csv.DictReader(fh):
                if r["gate"] != "accepted" or r["success"] != "1":
                    continue
                sig = [float(r[k]) for k in SIG]
                if min(sig) <= 0.0:
                    continue
                for k in range(6):
                    z[k].append(abs(float(r[ERR[k]])) / sig[k])
    n = len(z[0])
    if not n:
        print("no accepted successful registration with a covariance")
        return
    print("%d registrations; per axis: %% beyond 3 sd, factor on the variance for <= 1 %%:" % n)
    worst = 0.0
    for k, name in enumerate(AXES):
        beyond = 100.0 * sum(v > 3.0 for v in z[k]) / n
        # The 99th percentile of |z| must be <= 3 sd: variance factor (q99 / 3)^2.
        factor = (quantile(z[k], 0.99) / 3.0) ** 2
        worst = max(worst, factor)
        print("  %-2s %5.1f %%  x %.1f" % (name, beyond, factor))
    print("covariance_scale factor for every axis: %.1f (times the run's covariance_scale)" % worst)


def pct(part, whole):
    return 100.0 * part / max(whole, 1)


def targets(paths):
    by = OrderedDict()
    for path in paths:
        with open(path) as fh:
            for r in csv.DictReader(fh):
                by.setdefault(r["scene"], []).append(r)
    print("| scene | n | success, big starts | success, all | accepted: Es median / p95 [m] | "
          "Ea median / p95 [deg] | false accepts | false rejects | worst axis > 3 sd | misses |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene, rows in sorted(by.items()):
        ok = [r["success"] == "1" for r in rows]
        acc = [r for r in rows if r["gate"] == "accepted"]
        big = [r["success"] == "1" for r in rows if r["bounds"] == "big"]
        fa = sum(r["success"] != "1" for r in acc)
        fr = sum(s and r["gate"] != "accepted" for r, s in zip(rows, ok))
        es = [float(r["Es_m"]) for r in acc]
        ea = [float(r["Ea_deg"]) for r in acc]
        per_axis = [0] * 6
        for r in acc:
            for k in range(6):
                sig = float(r[SIG[k]])
                per_axis[k] += sig > 0.0 and abs(float(r[ERR[k]])) > 3.0 * sig
        worst = max(per_axis)
        misses = []
        if pct(sum(big), len(big)) < 99.5:
            misses.append("success")
        if acc and (quantile(es, 0.5) > 0.02 or quantile(ea, 0.5) > 0.1 or
                    quantile(es, 0.95) > 0.05 or quantile(ea, 0.95) > 0.3):
            misses.append("accuracy")
        if fa:
            misses.append("false accepts")
        if pct(fr, sum(ok)) > 1.0:
            misses.append("false rejects")
        if pct(worst, len(acc)) > 1.0:
            misses.append("calibration (%s)" % AXES[per_axis.index(worst)])
        print("| %s | %d | %.1f %% | %.1f %% | %s | %s | %d | %d (%.1f %%) | %.1f %% | %s |" % (
            scene, len(rows), pct(sum(big), len(big)), pct(sum(ok), len(rows)),
            "%.3f / %.3f" % (quantile(es, 0.5), quantile(es, 0.95)) if acc else "-",
            "%.2f / %.2f" % (quantile(ea, 0.5), quantile(ea, 0.95)) if acc else "-",
            fa, fr, pct(fr, sum(ok)), pct(worst, len(acc)), ", ".join(misses) or "none"))


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
    elif len(sys.argv) >= 3 and sys.argv[1] == "--targets":
        targets(sys.argv[2:])
    elif len(sys.argv) >= 3 and sys.argv[1] == "--calibrate":
        calibrate(sys.argv[2:])
    elif len(sys.argv) in (3, 4):
        plot(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else sys.argv[2])
    else:
        sys.exit(__doc__)
