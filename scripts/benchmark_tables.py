#!/usr/bin/env python3
"""BENCHMARK.md's tables from the folder scripts/benchmarks.sh writes (CSVs and logs).

usage: /usr/bin/python3 scripts/benchmark_tables.py [OUT_DIR] [--section NAME]

OUT_DIR defaults to docs/results. NAME: real_pairs (accuracy on real pairs, speed per vector
path and thread count, where the time goes), scenes, sequences, sweeps or rate; all by default.
The scene tables are scripts/plot_scenes.py --targets' own, the sequence table
scripts/plot_sequence.py --table's (both imported, not copied); success everywhere is
Es < 0.10 m and Ea < 1 deg (the paper's eqs. 7-8).
"""
import argparse
import contextlib
import csv
import io
import math
import os
import re
import statistics
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_scenes  # noqa: E402  (--targets: the scene benchmark's table; quantile())
import plot_sequence  # noqa: E402  (--table: the sequence summary's table)

quantile = plot_scenes.quantile  # the tools' quantile (core/metrics.h): index floor(q n)
SECTIONS = ("real_pairs", "scenes", "sequences", "sweeps", "covariance", "rate")


def read_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def value(row, key):
    """The column as a float, None when the CSV has no such column or it is empty."""
    v = row.get(key)
    return float(v) if v not in (None, "") else None


def success(row):
    return float(row["Es_m"]) < 0.10 and float(row["Ea_deg"]) < 1.0


def span(values, fmt):
    """'a-b' (or 'a' when equal) of the formatted smallest and largest value."""
    lo, hi = fmt % min(values), fmt % max(values)
    return lo if lo == hi else "%s-%s" % (lo, hi)


def files(folder, pattern):
    if not os.path.isdir(folder):
        return []
    return sorted(os.path.join(folder, f) for f in os.listdir(folder) if re.fullmatch(pattern, f))


def missing(folder):
    print("(no results: %s is missing or empty)\n" % folder)


def grouped(rows, *keys):
    """rows grouped by the key columns, in order of first appearance."""
    out = {}
    for r in rows:
        out.setdefault(tuple(r[k] for k in keys), []).append(r)
    return out


def log_path(csv_path):
    return csv_path[:-len(".csv")] + ".log"


def simd_in_log(path):
    """The vector path a tool's log reports, or '?'."""
    try:
        with open(path) as fh:
            m = re.search(r"SIMD path:? (\w+)", fh.read())
    except OSError:
        return "?"
    return m.group(1) if m else "?"


# --- rotations, for the repeatability (as core/metrics.cpp repeatability()) -----------------

def quat_matrix(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [list(r) for r in zip(*a)]


def rotation_vector(r):
    """The angle-axis vector of a rotation matrix (angles below pi, as here)."""
    c = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0))
    angle = math.acos(c)
    v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    s = math.sin(angle)
    f = 0.5 if s < 1e-12 else angle / (2.0 * s)
    return [f * x for x in v]


def rotation_matrix(w):
    angle = math.sqrt(sum(x * x for x in w))
    if angle == 0.0:
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    x, y, z = (c / angle for c in w)
    h = math.sin(angle / 2.0)
    return quat_matrix(x * h, y * h, z * h, math.cos(angle / 2.0))


def repeatability(rows):
    """Median distance [m] and angle [deg] of the estimates to their own median pose, or None
    when the CSV holds no estimate (older CSVs)."""
    if not rows or value(rows[0], "qw") is None:
        return None
    ts = [[float(r[k]) for k in ("tx", "ty", "tz")] for r in rows]
    rs = [quat_matrix(*(float(r[k]) for k in ("qx", "qy", "qz", "qw"))) for r in rows]
    r0t = transpose(rs[0])
    ws = [rotation_vector(mul(r, r0t)) for r in rs]
    t_med = [quantile([t[k] for t in ts], 0.5) for k in range(3)]
    w_med = [quantile([w[k] for w in ws], 0.5) for k in range(3)]
    r_med_t = transpose(mul(rotation_matrix(w_med), rs[0]))
    dm = [math.dist(t, t_med) for t in ts]
    dd = [math.degrees(math.sqrt(sum(x * x for x in rotation_vector(mul(r, r_med_t))))) for r in rs]
    return quantile(dm, 0.5), quantile(dd, 0.5)


# --- real pairs --------------------------------------------------------------------------------

# <folder>.csv, <folder>_<path>_t<threads>.csv, <folder>_seed<N>.csv (scripts/benchmarks.sh)
BENCH_CSV = (r"(?P<folder>.+?)"
             r"(?:_(?P<path>avx512|avx2|portable)_t(?P<threads>\d+)|_seed(?P<seed>\d+))?\.csv")
# A folder with more pairs than this (a sequence's consecutive scans) gets one pooled row per
# method: successes summed, medians over every trial, the worst pair's repeatability.
MAX_LISTED_PAIRS = 4
PATHS = (("avx512", "2", "AVX-512, 2 thr"), ("avx2", "2", "AVX2, 2 thr"),
         ("portable", "2", "portable, 2 thr"), ("avx2", "1", "AVX2, 1 thr"),
         ("portable", "1", "portable, 1 thr"))


def pair_label(folder, pair):
    return "%s %s" % (folder, pair.replace(".pcd", "").replace(".ply", "").replace("->", "→"))


def real_pair_runs(folder):
    """The benchmark CSVs by kind: {'main': {folder: csv}, 'paths': {(folder, path, threads):
    csv}, 'seeds': {folder: [(seed, csv)]}}."""
    runs = {"main": {}, "paths": {}, "seeds": {}}
    for path in files(folder, r".+\.csv"):
        m = re.fullmatch(BENCH_CSV, os.path.basename(path))
        if m.group("path"):
            runs["paths"][(m.group("folder"), m.group("path"), m.group("threads"))] = path
        elif m.group("seed"):
            runs["seeds"].setdefault(m.group("folder"), []).append((int(m.group("seed")), path))
        else:
            runs["main"][m.group("folder")] = path
    return runs


def is_cube(method):
    return method.startswith("cubes")


def by_pair(rows):
    """{pair: its rows}."""
    return {pair: sel for (pair,), sel in grouped(rows, "pair").items()}


def pool(groups):
    """{pair: rows} as is, or {'<n> pairs (pooled)': every row} beyond MAX_LISTED_PAIRS."""
    if len(groups) <= MAX_LISTED_PAIRS:
        return groups
    return {"%d pairs (pooled)" % len(groups): [r for sel in groups.values() for r in sel]}


def accuracy_table(runs):
    print("### Accuracy on real pairs\n")
    print("Each pair from the same seeded guesses (+-1 m / +-8 deg) for every method, in one run "
          "on the default vector path. Time ratio: the method's median time over the cube "
          "method's (the first cube method of the run). Repeatability: the median distance of "
          "the estimates to their own median pose. Largest translation sd: the cube method's "
          "covariance, median over the trials.\n")
    print("| pair | method | successes | Es / Ea median | median time | time / cubes' | "
          "repeatability | largest translation sd (median) |")
    print("|---|---|---|---|---|---|---|---|")
    for folder, path in sorted(runs["main"].items()):
        rows = read_rows(path)
        for (bounds,), bound_rows in grouped(rows, "bounds").items():
            pairs = by_pair(bound_rows)
            pooled = len(pairs) > MAX_LISTED_PAIRS
            for pair, pair_rows in pool(pairs).items():
                accuracy_rows(folder, pair, bounds, pair_rows,
                              list(pairs.values()) if pooled else [pair_rows])
    print()


def accuracy_rows(folder, pair, bounds, pair_rows, per_pair):
    """One row per method of `pair_rows`; repeatability: the worst of `per_pair`'s groups."""
    cube_time = None
    for (method,), sel in grouped(pair_rows, "method").items():
        t = statistics.median(float(r["time_s"]) for r in sel)
        if is_cube(method) and cube_time is None:
            cube_time = t
        reps = [repeatability([r for r in g if r["method"] == method]) for g in per_pair]
        rep = None if None in reps else (max(x[0] for x in reps), max(x[1] for x in reps))
        sd = [value(r, "sigma_m") for r in sel]
        sd_cell = ("%.2f cm" % (100 * statistics.median(sd))
                   if is_cube(method) and None not in sd else "-")
        print("| %s%s | %s | %d/%d | %.2f cm / %.2f° | %.1f ms | %s | %s | %s |" % (
            pair_label(folder, pair), "" if bounds == "big" else " (%s)" % bounds, method,
            sum(map(success, sel)), len(sel),
            100 * statistics.median(float(r["Es_m"]) for r in sel),
            statistics.median(float(r["Ea_deg"]) for r in sel), 1e3 * t,
            "%.1f×" % (t / cube_time) if cube_time else "-",
            "%.1f mm / %.4f°" % (1e3 * rep[0], rep[1]) if rep else "-", sd_cell))


def seeds_table(runs):
    if not runs["seeds"]:
        return
    print("### The cube method from several trial seeds\n")
    print("| pair | successes per trial seed | all seeds | Es median, range over the seeds |")
    print("|---|---|---|---|")
    total_ok = total_n = 0
    for folder in sorted(runs["seeds"]):
        by_seed = []
        if folder in runs["main"]:
            by_seed.append((1, runs["main"][folder]))
        by_seed += sorted(runs["seeds"][folder])
        per_pair = {}
        for seed, path in by_seed:
            rows = [r for r in read_rows(path) if is_cube(r["method"]) and r["bounds"] == "big"]
            first = rows[0]["method"] if rows else None
            for pair, sel in pool(by_pair([r for r in rows if r["method"] == first])).items():
                per_pair.setdefault(pair, []).append((seed, sel))
        for pair, seeds in per_pair.items():
            ok = [sum(map(success, sel)) for _, sel in seeds]
            n = [len(sel) for _, sel in seeds]
            es = [statistics.median(float(r["Es_m"]) for r in sel) for _, sel in seeds]
            total_ok, total_n = total_ok + sum(ok), total_n + sum(n)
            print("| %s | %s | %d/%d (seeds %s) | %s cm |" % (
                pair_label(folder, pair),
                ", ".join("%d: %d/%d" % (s, k, m) for (s, _), k, m in zip(seeds, ok, n)),
                sum(ok), sum(n), span([s for s, _ in seeds], "%d"),
                span([100 * e for e in es], "%.2f")))
    print("\nAll pairs and seeds: %d/%d successes.\n" % (total_ok, total_n))


def cube_medians(path):
    """{pair: (median time, successes, trials, rows)} of the first cube method of a run."""
    rows = [r for r in read_rows(path) if is_cube(r["method"]) and r["bounds"] == "big"]
    first = rows[0]["method"] if rows else None
    return {pair: (statistics.median(float(r["time_s"]) for r in sel), sum(map(success, sel)),
                   len(sel), sel)
            for pair, sel in pool(by_pair([r for r in rows if r["method"] == first])).items()}


def speed_table(runs):
    print("### Speed per vector path and thread count\n")
    if not runs["paths"]:
        print("(no per-path run)\n")
        return
    present = [p for p in PATHS if any(k[1:] == p[:2] for k in runs["paths"])]
    folders = sorted({k[0] for k in runs["paths"]})
    print("The cube method's median time of 25 trials (grids built and scan collapsed inside "
          "the timed call), one run per path and thread count; the first column is the run with "
          "the peers, on the default path its log names.\n")
    print("| pair | default path, with the peers | %s | successes, every path |" %
          " | ".join(p[2] for p in present))
    print("|---|---|%s---|" % ("---|" * len(present)))
    ratios = {"avx512": [], "portable": [], "one thread": [], "portable one thread": []}
    for folder in folders:
        main = runs["main"].get(folder)
        main_t = cube_medians(main) if main else {}
        per_path = {p[:2]: cube_medians(runs["paths"][(folder,) + p[:2]])
                    for p in present if (folder,) + p[:2] in runs["paths"]}
        pairs = list(dict.fromkeys(pr for m in per_path.values() for pr in m))
        for pair in pairs:
            cells, ok, n = [], 0, 0
            for p in present:
                m = per_path.get(p[:2], {}).get(pair)
                cells.append("%.1f ms" % (1e3 * m[0]) if m else "-")
                if m:
                    ok, n = ok + m[1], n + m[2]
            default = main_t.get(pair)
            default_cell = ("%.1f ms (%s)" % (1e3 * default[0], simd_in_log(log_path(main)))
                            if default else "-")
            print("| %s | %s | %s | %d/%d |" % (
                pair_label(folder, pair), default_cell, " | ".join(cells), ok, n))
            t = {k: v[pair][0] for k, v in per_path.items() if pair in v}
            if ("avx2", "2") in t:
                for key, name in ((("avx512", "2"), "avx512"), (("portable", "2"), "portable"),
                                  (("avx2", "1"), "one thread")):
                    if key in t:
                        ratios[name].append(t[key] / t[("avx2", "2")])
            if ("portable", "2") in t and ("portable", "1") in t:
                ratios["portable one thread"].append(t[("portable", "1")] / t[("portable", "2")])
    said = ["%s %s× the AVX2 2-thread time" % (name, span(v, "%.2f"))
            for name, v in (("AVX-512", ratios["avx512"]), ("portable", ratios["portable"]),
                            ("one thread (AVX2)", ratios["one thread"])) if v]
    if ratios["portable one thread"]:
        said.append("portable one thread %s× portable two"
                    % span(ratios["portable one thread"], "%.2f"))
    if said:
        print("\nRatios over the pairs: %s.\n" % "; ".join(said))
    else:
        print()


def stages_table(runs):
    print("### Where the time goes\n")
    sources = {}
    for folder in sorted(set(runs["main"]) | {k[0] for k in runs["paths"]}):
        path = runs["paths"].get((folder, "avx2", "2")) or runs["main"].get(folder)
        if path:
            sources[folder] = path
    if not sources:
        print("(no run)\n")
        return
    print("Medians of the cube method's 25 trials, from the AVX2 2-thread run (the default-path "
          "run where there is none); the rest: reference grids and plane map built, scan "
          "collapsed (the total's median minus the stages' medians).\n")
    print("| pair | run | total | coarse | refine | polish | the rest | coarse + refine | "
          "polish share |")
    print("|---|---|---|---|---|---|---|---|---|")
    for folder, path in sources.items():
        for pair, (t, _, _, sel) in cube_medians(path).items():
            st = []
            for key in ("time_coarse_s", "time_refine_s", "time_polish_s"):
                v = [value(r, key) for r in sel]
                st.append(statistics.median(v) if None not in v else None)
            if None in st:
                print("| %s | %s | %.1f ms | - | - | - | - | - | - |" % (
                    pair_label(folder, pair), os.path.basename(path), 1e3 * t))
                continue
            print("| %s | %s | %.1f ms | %.1f ms | %.1f ms | %.1f ms | %.1f ms | %.0f %% | "
                  "%.0f %% |" % (
                pair_label(folder, pair), os.path.basename(path), 1e3 * t, 1e3 * st[0],
                1e3 * st[1], 1e3 * st[2], 1e3 * (t - sum(st)), 100 * (st[0] + st[1]) / t,
                100 * st[2] / t))
    print()


def real_pairs(out):
    folder = os.path.join(out, "real_pairs")
    runs = real_pair_runs(folder)
    if not (runs["main"] or runs["paths"]):
        missing(folder)
        return
    accuracy_table(runs)
    seeds_table(runs)
    speed_table(runs)
    stages_table(runs)


# --- scenes ------------------------------------------------------------------------------------

def targets_lines(paths):
    """plot_scenes.py --targets' table, as lines."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        plot_scenes.targets(paths)
    return buf.getvalue().splitlines()


def repeat_table(path):
    """The repeatability groups of scene_benchmark --repeat's log (not in its CSV)."""
    with open(path) as fh:
        text = fh.read()
    m = re.search(r"--repeat (\d+)", text)
    starts = m.group(1) if m else "?"
    groups = []
    for line in text.splitlines():
        tok = re.sub(r"\|\s+", "|", line).split()
        # scene motion bounds ok/n Es Ea median_s acc FA FR >3sd sd rep
        if len(tok) == 13 and tok[2] in ("big", "small") and "|" in tok[12]:
            rep_m, rep_deg = (float(x) for x in tok[12].split("|"))
            groups.append((tok[0], tok[1], tok[2], tok[3], rep_m, rep_deg))
    if not groups:
        print("(no repeatability in %s)\n" % path)
        return
    csv_path = path[:-len(".log")] + ".csv"
    pairs = len(read_rows(csv_path)) if os.path.exists(csv_path) else "?"
    print("Each of %s pairs registered from %s starts (the first one is the CSV's); per group, "
          "the median over its pairs of each pair's median distance to its own median pose.\n"
          % (pairs, starts))
    print("| scene | motion | starts | successes | repeatability [mm] | [deg] |")
    print("|---|---|---|---|---|---|")
    for scene, motion, bounds, ok, rep_m, rep_deg in groups:
        print("| %s | %s | %s | %s | %.1f | %.4f |"
              % (scene, motion, bounds, ok, 1e3 * rep_m, rep_deg))
    print("\nRange over the groups: %s mm / %s°.\n" % (
        span([1e3 * g[4] for g in groups], "%.1f"), span([g[5] for g in groups], "%.4f")))


def scenes(out):
    folder = os.path.join(out, "scenes")
    paper = files(folder, r"scenes_default\.csv")
    robot = files(folder, r"scenes_robot(_seed\d+)?\.csv")
    artefacts = files(folder, r"scenes_artefacts(_seed\d+)?\.csv")
    if not (paper or robot or artefacts):
        missing(folder)
        return
    if paper:
        print("### The paper's four scene types (%s)\n" % ", ".join(map(os.path.basename, paper)))
        print("\n".join(targets_lines(paper)) + "\n")
    # The robot worlds and the runs with the sensor's artefacts in one table, a column naming
    # the run, each family's CSVs (trial seeds) pooled.
    runs = [(name, paths) for name, paths in (("robot", robot), ("artefacts", artefacts)) if paths]
    if runs:
        print("### The six robot worlds and all ten types with the sensor's artefacts "
              "(pooled: %s)\n" % "; ".join(", ".join(map(os.path.basename, p)) for _, p in runs))
        for k, (name, paths) in enumerate(runs):
            lines = targets_lines(paths)
            if k == 0:
                print("| scene | run | " + lines[0][2:].split(" | ", 1)[1])
                print("|---" + lines[1])
            for line in lines[2:]:
                scene, rest = line[2:].split(" | ", 1)
                print("| %s | %s | %s" % (scene, name, rest))
        print()
    rep = os.path.join(folder, "scenes_repeat.log")
    if os.path.exists(rep):
        print("### Repeatability\n")
        repeat_table(rep)


# --- sequences ---------------------------------------------------------------------------------

def rpe(r, length):
    pct, deg = r["rpe%d_pct" % length], r["rpe%d_deg_m" % length]
    return None if pct == "" else (float(pct), float(deg))


def rpe_cell(r, length):
    v = rpe(r, length)
    return "-" if v is None else "%.2f %% / %.4f deg/m" % v


def sequences(out):
    folder = os.path.join(out, "sequences")
    summaries = files(folder, r".+_summary\.csv")
    if not summaries:
        missing(folder)
        return
    # BENCHMARK.md's order: "big" odometry in park, natural, hall, urban; without odometry;
    # the real sequences.
    scene_rank = {"park": 0, "natural": 1, "hall": 2, "urban": 3}

    def rank(path):
        name = os.path.basename(path)
        m = re.fullmatch(r"sim_(big|cv)_(\w+?)_summary\.csv", name)
        if m:
            return (0 if m.group(1) == "big" else 1, scene_rank.get(m.group(2), 9), name)
        return (2 if name.startswith("real_") else 3, 0, name)

    summaries.sort(key=rank)
    runs = [(label, sel) for path in summaries
            for (label,), sel in grouped(read_rows(path), "label").items()]
    print("### Drift with \"big\" odometry: the cube method and the best peer\n")
    print("RPE: mean relative pose error over all segments of 10 / 100 m (% of the distance, "
          "deg/m); best peer: the lowest translation RPE (and the lowest rotation RPE when "
          "another peer has it) over the longest segments the run has.\n")
    print("| run | scans | cubes, RPE 100 m | cubes, RPE 10 m | cubes: rejected (accepted) | ATE | "
          "best peer (rejected) |")
    print("|---|---|---|---|---|---|---|")
    for label, sel in runs:
        sel = [r for r in sel if r["odometry"] == "big"]
        cubes = next((r for r in sel if r["method"] == "cubes"), None)
        if cubes is None:
            continue
        length = next((n for n in (100, 50, 10) if rpe(cubes, n)), None)
        peers = [r for r in sel if not is_cube(r["method"]) and length and rpe(r, length)]
        best = ""
        if peers:
            by_pct = min(peers, key=lambda r: rpe(r, length)[0])
            by_deg = min(peers, key=lambda r: rpe(r, length)[1])
            best = "; ".join("%s %s (%s)" % (r["method"], rpe_cell(r, length), r["rejected"])
                             for r in ([by_pct] if by_pct is by_deg else [by_pct, by_deg]))
            if length != 100:
                best += " (RPE %d m)" % length
        print("| %s | %s | %s | %s | %s (%s) | %.3f m | %s |" % (
            label, cubes["scans"], rpe_cell(cubes, 100), rpe_cell(cubes, 10), cubes["rejected"],
            cubes["accepted"], float(cubes["ate_m"]), best or "-"))
    print("\n### Every run (scripts/plot_sequence.py --table)\n")
    # plot_sequence.py --table reads one summary: the run's summaries, concatenated.
    with tempfile.NamedTemporaryFile("w", suffix=".csv", newline="", delete=False) as tmp:
        writer = csv.DictWriter(tmp, fieldnames=list(runs[0][1][0].keys()))
        writer.writeheader()
        for _, sel in runs:
            writer.writerows(sel)
    try:
        plot_sequence.table(tmp.name)
    finally:
        os.unlink(tmp.name)
    print()
    work_table(folder)


def work_table(folder):
    """Where the online step's time goes: the cube method's work columns per scan."""
    print("### Where the online step's time goes (the cube method, every scan)\n")
    print("Medians over the scans that ran the stage (count in brackets); coarse, refine and "
          "polish inside all align() calls of the step.\n")
    print("| run | odometry | align() calls / search attempts per scan (mean) | registration | "
          "no-motion searches | keyframe submap, median / p95 | coarse | refine | polish | "
          "whole step, median / p95 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ms = lambda v: "%.1f ms" % (1e3 * v)  # noqa: E731
    for path in files(folder, r"(sim_(big|cv)_\w+|real_\w+)\.csv"):
        rows = [r for r in read_rows(path) if r["method"] == "cubes" and r.get("aligns") not in (None, "")]
        if not rows or value(rows[0], "coarse_s") is None:
            continue
        ran = [r for r in rows if int(r["aligns"]) > 0]

        def med(key, sel):
            v = [float(r[key]) for r in sel]
            return "%s (%d)" % (ms(quantile(v, 0.5)), len(v)) if v else "never"
        cand = [r for r in rows if float(r["candidate_s"]) > 0]
        ref = [float(r["reference_s"]) for r in rows if r["reference_built"] == "1"]
        step = [float(r["time_s"]) for r in rows]
        label = os.path.basename(path)[:-4]
        print("| %s | %s | %.2f / %.2f | %s | %s | %s | %s | %s | %s | %s / %s |" % (
            label, rows[0]["odometry"],
            statistics.mean(int(r["aligns"]) for r in rows),
            statistics.mean(int(r["searches"]) for r in rows),
            med("register_s", ran), med("candidate_s", cand),
            "%s / %s (%d)" % (ms(quantile(ref, 0.5)), ms(quantile(ref, 0.95)), len(ref)) if ref else "never",
            med("coarse_s", ran), med("refine_s", ran), med("polish_s", ran),
            ms(quantile(step, 0.5)), ms(quantile(step, 0.95))))
    print()


# --- sweeps ------------------------------------------------------------------------------------

def sweeps(out):
    folder = os.path.join(out, "sweeps")
    path = os.path.join(folder, "sweep_motion.csv")
    if not os.path.exists(path):
        missing(folder)
        return
    rows = read_rows(path)
    cells = grouped(rows, "odometry", "mode", "speed_mps", "yaw_rate_dps", "duration_s")
    scenes = sorted({r["scene"] for r in rows})
    print("### Sweeps taken while driving\n")
    print("%s, %d cells (speed, yaw rate, sweep duration) per odometry and mode; steady: "
          "increments 2 and later of each run; Es / Ea and step time: the cell's median over its "
          "steady increments (the mean of the two middle values for an even count), range over "
          "the cells.\n" % (", ".join(scenes), len({k[2:] for k in cells})))
    print("| odometry | mode | steady increments right | all increments accepted wrong | "
          "Es / Ea median, range over the cells | step time |")
    print("|---|---|---|---|---|---|")
    mode_order = {"deskew": 0, "rigid": 1, "static": 2}
    pairs = sorted({k[:2] for k in cells},
                   key=lambda k: (k[0] != "drift", mode_order.get(k[1], 3), k))
    for odometry, mode in pairs:
        sel = [r for r in rows if r["odometry"] == odometry and r["mode"] == mode]
        steady = [r for r in sel if int(r["k"]) >= 2]
        es, ea, t = [], [], []
        for key, cell in cells.items():
            if key[:2] != (odometry, mode):
                continue
            st = [r for r in cell if int(r["k"]) >= 2]
            es.append(statistics.median(float(r["Es_m"]) for r in st))
            ea.append(statistics.median(float(r["Ea_deg"]) for r in st))
            t.append(statistics.median(float(r["time_s"]) for r in st))
        # Accepted wrong: the registration itself off (Es_reg / Ea_reg, against the last
        # accepted scan), not an increment that carries a rejected sweep's predicted pose.
        wrong = sum(r["accepted"] == "1" and not (float(r["Es_reg_m"]) < 0.10
                                                  and float(r["Ea_reg_deg"]) < 1.0) for r in sel)
        print("| %s | %s | %d/%d | %d/%d | %s cm / %s° | %s s |" % (
            odometry, mode, sum(r["success"] == "1" for r in steady), len(steady), wrong, len(sel),
            span([100 * e for e in es], "%.2f"), span(ea, "%.3f"), span(t, "%.2f")))
    # The target as the CTest sweep_motion_deskew checks it: the median (the tool's: the upper
    # middle value) of the steady de-skewed increments up to 1 m/s and 20 deg/s.
    print()
    for odometry in sorted({r["odometry"] for r in rows}):
        st = [r for r in rows if r["odometry"] == odometry and r["mode"] == "deskew"
              and int(r["k"]) >= 2 and float(r["speed_mps"]) <= 1
              and abs(float(r["yaw_rate_dps"])) <= 20]
        if st:
            es = quantile([float(r["Es_m"]) for r in st], 0.5)
            ea = quantile([float(r["Ea_deg"]) for r in st], 0.5)
            print("Target, %s odometry, de-skewed up to 1 m/s and 20°/s: median Es %.2f cm, Ea "
                  "%.3f° (<= 2 cm, 0.1°: %s)." % (odometry, 100 * es, ea,
                                                   "met" if es <= 0.02 and ea <= 0.1 else "missed"))
    print()


# --- rate --------------------------------------------------------------------------------------

RATE_PATTERNS = {
    "rate": r"rate_feeder: ([\d.]+) Hz for ([\d.]+) s",
    "counts": r"published (\d+), answered (\d+) \(accepted (\d+)\), dropped by the matcher's "
              r"queue (\d+), unanswered (-?\d+)",
    "age": r"data age \(stamp -> pose\) \[ms\]: median ([\d.]+), p95 ([\d.]+), max ([\d.]+)",
    "registration": r"registration \[ms\]: median ([\d.]+), p95 ([\d.]+)",
    "hwm": r"VmHWM:\s*(\d+) kB",
    "load": r"load average before: (\S+)",
    "simd": r"SIMD path:? (\w+)|CSM_SIMD=(\w+)",
}


def rate(out):
    folder = os.path.join(out, "rate")
    logs = files(folder, r".+\.log")
    logs = [p for p in logs if not p.endswith(".stderr.log")]
    skipped = os.path.join(folder, "skipped.txt")
    print("### The nodelet at robot rates\n")
    if not logs:
        if os.path.exists(skipped):
            with open(skipped) as fh:
                print(fh.read().strip() + "\n")
        else:
            missing(folder)
        return
    print("| run | rate | published | answered (accepted) | dropped by the queue | data age "
          "median / p95 / max | registration median / p95 | manager peak RSS (VmHWM) | "
          "load before | path |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for path in logs:
        with open(path) as fh:
            text = fh.read()
        m = {k: re.search(p, text) for k, p in RATE_PATTERNS.items()}
        name = os.path.basename(path)[:-len(".log")]
        if not m["counts"]:
            print("| %s | (no result in the log) | | | | | | | | |" % name)
            continue
        published, answered, accepted, dropped = (int(m["counts"].group(i)) for i in range(1, 5))
        print("| %s | %s | %d | %d (%d) | %d (%.0f %%) | %s | %s | %s | %s | %s |" % (
            name, "%s Hz, %s s" % (m["rate"].group(1), m["rate"].group(2)) if m["rate"] else "?",
            published, answered, accepted, dropped, 100.0 * dropped / max(published, 1),
            "%s / %s / %s ms" % m["age"].groups() if m["age"] else "-",
            "%s / %s ms" % m["registration"].groups() if m["registration"] else "-",
            "%.1f MB" % (int(m["hwm"].group(1)) / 1024.0) if m["hwm"] else "-",
            m["load"].group(1) if m["load"] else "?",
            (m["simd"].group(1) or m["simd"].group(2)) if m["simd"] else "?"))
    print()


# --- covariance --------------------------------------------------------------------------------

CHAIN_AXES = ("x", "y", "z", "roll", "pitch", "yaw")


def chain_consistency_table(rows):
    """Per world (pooled over seeds, "small" and "drift" odometry, weighted by keyframes) and
    over all: within 1 sd and beyond 3 sd per axis, and the mean NEES."""
    rows = [r for r in rows if r["odometry"] in ("small", "drift")]
    worlds = []
    for r in rows:
        w = r["label"].rsplit("_", 1)[0]
        if w not in worlds:
            worlds.append(w)
    print("| world | runs | keyframes | within 1 sd [%%] %s | beyond 3 sd [%%] %s | NEES |"
          % (" ".join(CHAIN_AXES), " ".join(CHAIN_AXES)))
    print("|---|---|---|---|---|---|")

    def line(name, group):
        n = sum(int(r["keyframes"]) for r in group)
        if not n:
            return
        share = lambda key, a: sum(float(r[key + a]) * int(r["keyframes"]) for r in group) / n
        w1 = " ".join("%.0f" % (100 * share("within1_", a)) for a in CHAIN_AXES)
        b3 = " ".join("%.1f" % (100 * share("beyond3_", a)) for a in CHAIN_AXES)
        nees = sum(float(r["nees_mean"]) * int(r["keyframes"]) for r in group) / n
        print("| %s | %d | %d | %s | %s | %.1f |" % (name, len(group), n, w1, b3, nees))

    for w in worlds:
        line(w, [r for r in rows if r["label"].rsplit("_", 1)[0] == w])
    line("**all**", rows)
    print()


def anchored_table(rows):
    """Per odometry mode: the chain, the chain tied to the odometry and the odometry alone,
    medians over the runs of the largest position error (no alignment) and of RPE per 10 m."""
    print("| odometry | runs | row | max position error [m], median (range) | RPE10 [%] median |")
    print("|---|---|---|---|---|")
    for odo in ("drift", "dgps"):
        for method in ("cubes", "cubes-anchored", "odometry"):
            group = [r for r in rows if r["odometry"] == odo and r["method"] == method]
            if not group:
                continue
            err = [float(r["max_error_m"]) for r in group if r["max_error_m"]]
            rpe = [float(r["rpe10_pct"]) for r in group if r["rpe10_pct"]]
            print("| %s | %d | %s | %.2f (%s) | %s |" % (
                odo, len(group), method, statistics.median(err), span(err, "%.2f"),
                "%.2f" % statistics.median(rpe) if rpe else "-"))
    print()


def unseen_table(path):
    """A single registration's calibration per scene: accepted right results (success) with a
    covariance, the share beyond 3 predicted sd per axis and on the worst axis."""
    rows = read_rows(path)
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    err = ("ex_m", "ey_m", "ez_m", "erx_rad", "ery_rad", "erz_rad")
    sig = ("sx_m", "sy_m", "sz_m", "srx_rad", "sry_rad", "srz_rad")
    print("| scene | accepted right | beyond 3 sd [%%] %s | worst axis beyond 3 sd [%%] |"
          % " ".join(CHAIN_AXES))
    print("|---|---|---|---|")
    total = [0, [0] * 6, 0]
    for scene in scenes:
        n, per_axis, worst = 0, [0] * 6, 0
        for r in rows:
            if r["scene"] != scene or r["gate"] != "accepted" or r["success"] != "1":
                continue
            s = [float(r[k]) for k in sig]
            if min(s) <= 0.0:
                continue
            z = [abs(float(r[e])) / sd for e, sd in zip(err, s)]
            n += 1
            for k in range(6):
                per_axis[k] += z[k] > 3.0
            worst += max(z) > 3.0
        total[0] += n
        total[1] = [a + b for a, b in zip(total[1], per_axis)]
        total[2] += worst
        if n:
            print("| %s | %d | %s | %.1f |" % (scene, n, " ".join(
                "%.1f" % (100.0 * v / n) for v in per_axis), 100.0 * worst / n))
    if total[0]:
        print("| **all** | %d | %s | %.1f |" % (total[0], " ".join(
            "%.1f" % (100.0 * v / total[0]) for v in total[1]), 100.0 * total[2] / total[0]))
    print()


def covariance(out):
    folder = os.path.join(out, "covariance")
    consistency = os.path.join(folder, "chain_consistency.csv")
    summary = os.path.join(folder, "chain_summary.csv")
    unseen = os.path.join(folder, "scenes_unseen.csv")
    if not any(os.path.exists(p) for p in (consistency, summary, unseen)):
        missing(folder)
        return
    if os.path.exists(consistency):
        print("### Covariance along the chain (chain_consistency.csv)\n")
        chain_consistency_table(read_rows(consistency))
    if os.path.exists(summary):
        print("### The chain tied to the odometry (chain_summary.csv)\n")
        anchored_table(read_rows(summary))
    if os.path.exists(unseen):
        print("### A single registration's covariance on unseen worlds (scenes_unseen.csv)\n")
        unseen_table(unseen)


def header(out, section):
    """The lines of SECTION/run.txt that say where and when its figures were measured."""
    path = os.path.join(out, section, "run.txt")
    if not os.path.exists(path):
        print("(no %s/run.txt)\n" % section)
        return
    with open(path) as fh:
        keys = ("mode", "commit", "tree", "started", "cpu", "cores", "finished")
        keep = [line.rstrip() for line in fh if line.split(":", 1)[0] in keys]
    print("\n".join("    " + line for line in keep) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default="docs/results", metavar="OUT_DIR")
    parser.add_argument("--section", choices=SECTIONS)
    args = parser.parse_args()
    if not os.path.isdir(args.out):
        sys.exit("benchmark_tables: %s is not a directory" % args.out)
    print("# Benchmark tables: %s\n" % args.out)
    for name in SECTIONS:
        if args.section in (None, name):
            print("## %s\n" % name)
            header(args.out, name)
            globals()[name](args.out)


if __name__ == "__main__":
    main()
