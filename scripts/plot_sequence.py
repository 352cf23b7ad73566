#!/usr/bin/env python3
"""Trajectories (x-y) of every method against the truth, one panel per sequence_benchmark CSV,
and the summary CSV as a markdown table (with each cube method's accepted results that are
wrong and rejected ones that are right, beyond / within 0.10 m and 1 deg of the truth).

usage: /usr/bin/python3 scripts/plot_sequence.py OUT.png RUN.csv [RUN.csv ...]
       /usr/bin/python3 scripts/plot_sequence.py --table SUMMARY.csv
       /usr/bin/python3 scripts/plot_sequence.py --steps RUN.csv [RUN.csv ...]
--steps counts, per method, the increments between consecutive scans whose planar error
(x, y, yaw) against the truth's is >= 0.1 m or >= 1 deg: one bad registration each.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def table(path):
    def cell(pct, deg):
        return "-" if pct == "" else "%.2f %% / %.4f" % (float(pct), float(deg))

    def p95(r):  # summaries written before the column have none
        return "-" if r.get("p95_time_s") in (None, "") else "%.3f" % float(r["p95_time_s"])

    def judged(r):  # accepted wrong / rejected right: the cube methods, in newer summaries
        if r.get("accepted_wrong") in (None, ""):
            return "-"
        return "%s / %s" % (r["accepted_wrong"], r["rejected_right"])

    print("| run | odometry | method | scans | m | accepted / rejected | accepted wrong / "
          "rejected right | RPE 10 m | RPE 50 m | RPE 100 m | ATE m | standing still m / deg | "
          "median s | p95 s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    with open(path) as fh:
        for r in csv.DictReader(fh):
            print("| %s | %s | %s | %s | %.0f | %s / %s | %s | %s | %s | %s | %.3f | %s | %.3f | %s |" % (
                r["label"], r["odometry"], r["method"], r["scans"], float(r["length_m"]),
                r["accepted"], r["rejected"], judged(r), cell(r["rpe10_pct"], r["rpe10_deg_m"]),
                cell(r["rpe50_pct"], r["rpe50_deg_m"]), cell(r["rpe100_pct"], r["rpe100_deg_m"]),
                float(r["ate_m"]),
                "-" if r["still_scans"] == "0" else "%.3f / %.2f" % (float(r["still_m"]), float(r["still_deg"])),
                float(r["median_time_s"]), p95(r)))


def planar(r, prefix):
    return float(r[prefix + "x"]), float(r[prefix + "y"]), math.radians(float(r[prefix + "yaw_deg"]))


def between(a, b):
    """Planar b relative to a."""
    dx, dy, c, s = b[0] - a[0], b[1] - a[1], math.cos(a[2]), math.sin(a[2])
    return c * dx + s * dy, -s * dx + c * dy, b[2] - a[2]


def steps(files):
    print("| run | odometry | method | increments off (>= 0.1 m or 1 deg) |")
    print("|---|---|---|---|")
    for f in files:
        runs = {}
        with open(f) as fh:
            for r in csv.DictReader(fh):
                runs.setdefault(r["method"], []).append(r)
        for name, rows in runs.items():
            off = 0
            for p, q in zip(rows, rows[1:]):
                t = between(planar(p, "truth_"), planar(q, "truth_"))
                e = between(planar(p, ""), planar(q, ""))
                err = between(t, e)
                yaw = (err[2] + math.pi) % (2 * math.pi) - math.pi
                off += math.hypot(err[0], err[1]) >= 0.1 or abs(math.degrees(yaw)) >= 1.0
            print("| %s | %s | %s | %d of %d |" % (rows[0]["label"], rows[0]["odometry"], name, off,
                                                   len(rows) - 1))


def plot(out, files):
    fig, axes = plt.subplots(len(files), 1, figsize=(10, 3.2 * len(files)), squeeze=False)
    for ax, f in zip(axes[:, 0], files):
        runs = {}
        with open(f) as fh:
            for r in csv.DictReader(fh):
                runs.setdefault(r["method"], []).append(r)
        first = next(iter(runs.values()))
        ax.plot([float(r["truth_x"]) for r in first], [float(r["truth_y"]) for r in first],
                "k-", lw=2, label="truth")
        for name, rows in runs.items():
            ax.plot([float(r["x"]) for r in rows], [float(r["y"]) for r in rows], lw=1, label=name)
        ax.set_title("%s, odometry %s" % (first[0]["label"], first[0]["odometry"]))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(out, dpi=90)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--table":
        table(sys.argv[2])
    elif len(sys.argv) >= 3 and sys.argv[1] == "--steps":
        steps(sys.argv[2:])
    elif len(sys.argv) >= 3:
        plot(sys.argv[1], sys.argv[2:])
    else:
        sys.exit(__doc__)
