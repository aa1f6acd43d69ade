#!/usr/bin/python3
"""Model 1 on the paper cell over eight seeds: the spread between trajectories.

Reads the archived runs of the headline sweep (seeds 1-3,
reports/study/paper/points) and of the extra-seed sweeps fixed in advance
(seeds 4-8: experiments/sweeps/paper_mn01_states.toml at Mn 0.1,
reports/study/paper/mn01_states/points; paper_model1_seeds.toml at the
other Mn, reports/study/paper/model1_seeds/points), and writes
reports/study/paper/model1_seeds.md: at Mn 0.1 each run's numbers, its
particle part in 50-strain blocks of the window and the mean over the
seeds with the standard error from their scatter (model1_mn01_windows.png:
each run's particle part in 10-strain bins); at every Mn the seed standard
deviation of seeds 1-3 against all seeds; and model 3 at Mn 0.1, whose
seeds 4-6 (paper_mn01_coupled_seeds.toml, mn01_coupled_seeds/points) were
fixed in advance too: each seed's run and three seeds against six.

With --runs the runs are read from the sweeps' run folders
(out/sweeps/paper_realistic, paper_mn01_states, paper_model1_seeds), as
`scripts/reproduce paper` leaves them, and a run's averaging window from its
timeseries.csv (the rows an archive's window_series.csv keeps).

usage: reports/paper_model1_seeds.py [paper folder, default reports/study/paper] [--runs]
"""
import csv
import json
import math
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


# the headline's archive and the extra-seed archives (scripts/paper_interim.py,
# EXTRA_SEEDS), and the sweeps whose run folders hold the same runs
FOLDERS = (("points", "paper_realistic"), ("mn01_states/points", "paper_mn01_states"),
           ("model1_seeds/points", "paper_model1_seeds"), ("mn01_coupled_seeds/points", "paper_mn01_coupled_seeds"))


# the long runs of model 3 at Mn 0.1 (experiments/sweeps/paper_mn01_long.toml, session 35): shown beside
# the point by the reading fixed in that file, never merged into it
LONG = ("mn01_long/points", "paper_mn01_long")


def combined(values, errors):
    """Seed mean and its error as the point's: max(combined within-run error, seed scatter / sqrt(n))."""
    n = len(values)
    within = math.sqrt(sum(e * e for e in errors)) / n
    return statistics.mean(values), max(within, statistics.stdev(values) / math.sqrt(n) if n > 1 else 0.0)


def model3_long(paper, from_runs, six, model1):
    """The reading of experiments/sweeps/paper_mn01_long.toml, as fixed there before its runs: L (the long
    runs' window mean) against P (the six-seed point); if P - L > 2 combined standard errors, model 3 at
    Mn 0.1 is not converged in strain at the design's windows, and D_1 = tau_1 / L - 1 is given beside."""
    folder = os.path.join("out", "sweeps", LONG[1]) if from_runs else os.path.join(paper, LONG[0])
    long = [(seed, d, json.load(open(os.path.join(d, "summary.json")))) for seed, d in run_dirs([folder], 0.1, "demsph_dd")]
    lines = ["### Where model 3 settles at Mn 0.1: the long runs", "",
             "experiments/sweeps/paper_mn01_long.toml (fixed before its runs, session 35): seeds 7 and 8, 800 strain "
             "units with 400 of warm-up; their reading is in that file."]
    if not long:
        return lines + ["", "No run has finished yet (none is archived: reports/study/paper/mn01_long/points).", ""]
    lines += ["", "| seed | total over 400-800 (Pa) | drift z | MSER-5 | last two 200-strain halves: difference "
              "(own SE) | 50-strain bins (Pa) |", "|---|---|---|---|---|---|"]
    for seed, d, s in long:
        rows = window_rows(d, s["warmup_strain"])
        strain = [float(r["strain"]) for r in rows]
        total = [float(r["stress_total_Pa"]) for r in rows]
        lo, hi = s["warmup_strain"], s["strain"]
        _, blocks = bins(strain, total, lo, hi, 50.0)
        _, halves = bins(strain, total, lo, hi, (hi - lo) / 2)
        # each half holds half the samples: its error is the window's times sqrt 2
        diff = (halves[1] - halves[0]) / (2.0 * s["stress_total_err"]) if s["stress_total_err"] > 0 else float("nan")
        lines.append(f"| {seed} | {s['stress_total']:.2f} ± {s['stress_total_err']:.2f} | "
                     f"{s['stress_total_drift_z']:+.2f} | {s['steady_mser_discard_fraction']:.3f} | {diff:+.2f} | "
                     + ", ".join(f"{b:.1f}" for b in blocks) + " |")
    L, eL = combined([s["stress_total"] for _, _, s in long], [s["stress_total_err"] for _, _, s in long])
    P, eP = combined([s["stress_total"] for s in six], [s["stress_total_err"] for s in six])
    t1, e1 = combined([s["stress_total"] for s in model1], [s["stress_total_err"] for s in model1])
    z = (P - L) / math.hypot(eP, eL)
    lines += ["", f"L = {L:.2f} ± {eL:.2f} Pa ({len(long)} of 2 runs); P = {P:.2f} ± {eP:.2f} Pa (the six seeds); "
              f"P - L = {P - L:+.2f} Pa = {z:+.2f} combined standard errors."]
    if len(long) < 2:
        lines.append("One of the two runs is still to come: the reading waits for both.")
    elif z > 2:
        d1 = t1 / L - 1
        ed1 = (t1 / L) * math.hypot(e1 / t1, eL / L)
        inside = d1 - 2 * ed1 <= -0.27 and d1 + 2 * ed1 >= -0.68
        lines.append(f"By the reading fixed in advance: **model 3 at Mn 0.1 is not converged in strain** at the design's "
                     f"windows. The point stays P; beside it, D_1 from the long runs = tau_1 / L - 1 = {d1:+.3f} ± "
                     f"{ed1:.3f} (tau_1 = {t1:.2f} ± {e1:.2f} Pa, model 1's {len(model1)} seeds): "
                     + ("inside" if inside else "**outside**") + " the claim's bound [-0.68, -0.27] to 2 standard errors.")
    else:
        lines.append("By the reading fixed in advance: P stands; L is shown beside it.")
    return lines + [""]


def roots(paper, from_runs):
    return [os.path.join("out", "sweeps", sweep) if from_runs else os.path.join(paper, archive)
            for archive, sweep in FOLDERS]


def run_dirs(folders, mn, model="dem_stokes"):
    """(seed, folder) of every run of `model` at Mn `mn` under `folders`, by seed."""
    out = [(seed, d) for folder in folders for seed in range(1, 100)
           if os.path.exists(os.path.join(d := os.path.join(folder, model, f"mn_{mn:g}_seed_{seed}"),
                                          "summary.json"))]
    return sorted(out)


def window_rows(d, warmup):
    """The rows of a run's averaging window: window_series.csv where an archive kept it, else the rows of
    timeseries.csv from the one before the first whose predecessor has reached the warm-up (as mrf's
    window_series_text takes them)."""
    path = os.path.join(d, "window_series.csv")
    if os.path.exists(path):
        return list(csv.DictReader(open(path)))
    rows = list(csv.DictReader(open(os.path.join(d, "timeseries.csv"))))
    first = next((r for r in range(len(rows))
                  if (float(rows[r - 1]["strain"]) if r else 0.0) >= warmup * (1 - 1e-12)), len(rows))
    return rows[max(first - 1, 0):]


def summaries(folders, mn, model="dem_stokes"):
    """(seed, summary) of every run of `model` at Mn `mn`."""
    return [(seed, json.load(open(os.path.join(d, "summary.json")))) for seed, d in run_dirs(folders, mn, model)]


def is_steady(s):
    return abs(s["stress_total_drift_z"]) < 3 and s["steady_mser_discard_fraction"] < 0.2


def model3_mn01(folders, paper, from_runs=False):
    """Model 3 at Mn 0.1: each seed's run and the seed standard deviation of seeds 1-3 against all, as
    experiments/sweeps/paper_mn01_coupled_seeds.toml asked to be reported beside its point, and each kept
    window's total wall stress in 10-strain bins (model3_mn01_windows.png)."""
    ss = summaries(folders, 0.1, "demsph_dd")
    if not ss:
        return []
    fig, ax = plt.subplots(figsize=(8, 4.5))
    missing = []
    for seed, d in run_dirs(folders, 0.1, "demsph_dd"):
        s = json.load(open(os.path.join(d, "summary.json")))
        if not (os.path.exists(os.path.join(d, "window_series.csv")) or os.path.exists(os.path.join(d, "timeseries.csv"))):
            missing.append(str(seed))
            continue
        rows = window_rows(d, s["warmup_strain"])
        strain = [float(r["strain"]) for r in rows]
        edges, fine = bins(strain, [float(r["stress_total_Pa"]) for r in rows], s["warmup_strain"], s["strain"], 10.0)
        ax.plot([0.5 * (a + b) for a, b in zip(edges[:-1], edges[1:])], fine, "o-", ms=3, label=f"seed {seed}")
    save_windows(fig, ax, "total wall stress (Pa), 10-strain bins", "Model 3", os.path.join(paper, "model3_mn01_windows.png"))
    lines = ["## Model 3 at Mn 0.1: three seeds against six", "",
             "Seeds 1-3 from the headline sweep (their last runs), seeds 4-6 from "
             "`experiments/sweeps/paper_mn01_coupled_seeds.toml` (200 strain units, 100 of warm-up; fixed in "
             "advance, session 33: the point takes every seed, whatever it gives). Particle part = total less the "
             "fluid part.", "",
             "| seed | strain (warm-up) | total (Pa) | particle part (Pa) | drift z | MSER-5 | steady |",
             "|---|---|---|---|---|---|---|"]
    for seed, s in ss:
        lines.append(f"| {seed} | {s['strain']:g} ({s['warmup_strain']:g}) | {s['stress_total']:.2f} ± "
                     f"{s['stress_total_err']:.2f} | {s['stress_total'] - s['stress_fluid']:.2f} | "
                     f"{s['stress_total_drift_z']:+.2f} | {s['steady_mser_discard_fraction']:.3f} | "
                     f"{'yes' if is_steady(s) else 'no'} |")
    lines.append("")
    for label, group in (("seeds 1-3", [s for sd, s in ss if sd <= 3]), (f"all {len(ss)} seeds", [s for _, s in ss])):
        tot = [s["stress_total"] for s in group]
        if len(tot) < 2:
            continue
        sd = statistics.stdev(tot)
        within = math.sqrt(sum(s["stress_total_err"] ** 2 for s in group)) / len(group)
        lines.append(f"- {label}: mean {statistics.mean(tot):.2f} Pa, seed standard deviation {sd:.2f} Pa, "
                     f"standard error of the mean {sd / math.sqrt(len(tot)):.2f} Pa (the runs' own errors alone: "
                     f"{within:.2f} Pa).")
    if len(ss) < 6:
        lines.append(f"- {6 - len(ss)} of the design's seeds still running or queued.")
    lines += ["", "![total wall stress per run](model3_mn01_windows.png)", ""]
    if missing:
        lines += [f"Not in the figure: seed(s) {', '.join(missing)}, whose runs predate the archived windows "
                  "(window_series.csv).", ""]
    return lines + model3_long(paper, from_runs, [s for _, s in ss], [s for _, s in summaries(folders, 0.1)])


def runs(folders):
    """(seed, summary, strain, particle part) of every run at Mn 0.1, over its averaging window."""
    out = []
    for seed, d in run_dirs(folders, 0.1):
        s = json.load(open(os.path.join(d, "summary.json")))
        rows = window_rows(d, s["warmup_strain"])
        out.append((seed, s, [float(r["strain"]) for r in rows], [float(r["stress_particles_Pa"]) for r in rows]))
    return out


def save_windows(fig, ax, ylabel, model, path):
    """Labels, legend and file of a figure of each seed's averaging window at Mn 0.1."""
    ax.set_xlabel("strain")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{model}, Mn 0.1, paper cell: the averaging window of each seed")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def bins(strain, values, lo, hi, width):
    edges = [lo + k * width for k in range(int(round((hi - lo) / width)) + 1)]
    means = []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = [v for x, v in zip(strain, values) if a <= x < b or (b == hi and x == hi)]
        means.append(sum(sel) / len(sel) if sel else float("nan"))
    return edges, means


def main():
    args = [a for a in sys.argv[1:] if a != "--runs"]
    paper = args[0] if args else "reports/study/paper"
    folders = roots(paper, "--runs" in sys.argv)
    rs = runs(folders)
    if not rs:
        print("paper_model1_seeds: no runs")
        return 0
    lines = ["# The spread between trajectories: model 1 over eight seeds (model 3 at Mn 0.1 at the end)", "", "## Mn 0.1", "",
             "Generated by `reports/paper_model1_seeds.py` from the archived runs of the headline sweep (seeds 1-3)",
             "and of `experiments/sweeps/paper_mn01_states.toml` (seeds 4-8, fixed in advance, session 31):",
             "paper cell, realistic path (1000 1/s), 400 strain units with 200 of warm-up, current code.",
             "Particle part = total wall stress less the imposed 100 Pa. Steady: drift |z| < 3 and MSER-5 < 0.2.", ""]
    lo, hi = 200.0, 400.0
    head = "| seed | total (Pa) | particle part (Pa) | drift z | MSER-5 | steady | " + " | ".join(
        f"{int(lo + 50 * k)}-{int(lo + 50 * (k + 1))}" for k in range(4)) + " |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    totals = []
    for seed, s, strain, part in rs:
        z, mser = s["stress_total_drift_z"], s["steady_mser_discard_fraction"]
        steady = abs(z) < 3 and mser < 0.2
        _, blocks = bins(strain, part, lo, hi, 50.0)
        lines.append(f"| {seed} | {s['stress_total']:.2f} ± {s['stress_total_err']:.2f} | "
                     f"{s['stress_particles']:.2f} ± {s['stress_particles_err']:.2f} | {z:+.2f} | {mser:.3f} | "
                     f"{'yes' if steady else 'no'} | " + " | ".join(f"{b:.2f}" for b in blocks) + " |")
        totals.append((s["stress_total"], s["stress_total_err"]))
        edges, fine = bins(strain, part, lo, hi, 10.0)
        ax.plot([0.5 * (a + b) for a, b in zip(edges[:-1], edges[1:])], fine, "o-", ms=3, label=f"seed {seed}")
    n = len(totals)
    mean = sum(t for t, _ in totals) / n
    lines.append("")
    if n > 1:
        sd = math.sqrt(sum((t - mean) ** 2 for t, _ in totals) / (n - 1))
        within = math.sqrt(sum(e * e for _, e in totals)) / n
        lines += [f"Over {n} seeds: mean {mean:.2f} Pa, seed standard deviation {sd:.2f} Pa, standard error of "
                  f"the mean from the scatter {sd / math.sqrt(n):.2f} Pa (the runs' own errors alone would give "
                  f"{within:.2f} Pa).", ""]
    lines += ["![particle part per run](model1_mn01_windows.png)", ""]
    lines += ["## Every Mn: three seeds against all", "",
              "Seeds 4-8 at Mn 1e-3, 1e-2, 1 and 10 from `experiments/sweeps/paper_model1_seeds.toml` (fixed in "
              "advance, session 31). SD = sample standard deviation of the runs' total wall stress; run error = the "
              "mean of the runs' own block-average errors.", "",
              "| Mn | seeds | mean (Pa) | SD, seeds 1-3 | SD, all seeds | run error | unsteady runs |",
              "|---|---|---|---|---|---|---|"]
    for mn in (1e-3, 1e-2, 0.1, 1.0, 10.0):
        ss = summaries(folders, mn)
        tot = [s["stress_total"] for _, s in ss]
        first = [s["stress_total"] for sd, s in ss if sd <= 3]
        bad = [str(sd) for sd, s in ss if not is_steady(s)]
        sd3 = f"{statistics.stdev(first):.3g}" if len(first) > 1 else ""
        sdall = f"{statistics.stdev(tot):.3g}" if len(tot) > 1 else ""
        err = sum(s["stress_total_err"] for _, s in ss) / len(ss) if ss else float("nan")
        lines.append(f"| {mn:g} | {len(ss)} | {sum(tot) / len(tot):.4g} | {sd3} | {sdall} | {err:.2g} | "
                     f"{', '.join(bad) if bad else 'none'} |")
    lines.append("")
    lines += model3_mn01(folders, paper, "--runs" in sys.argv)
    save_windows(fig, ax, "particle wall stress (Pa), 10-strain bins", "Model 1", os.path.join(paper, "model1_mn01_windows.png"))
    with open(os.path.join(paper, "model1_seeds.md"), "w") as fh:
        fh.write("\n".join(lines))
    print(f"paper_model1_seeds: {n} runs at Mn 0.1 -> {paper}/model1_seeds.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
