#!/usr/bin/python3
"""The coupled points at Mn 1e-3 of the paper-scale report: session 34's
one-window rule (each run averaged over strain 16-48) and the carrier
(experiments/sweeps/paper_common_low.toml: the points run again with the
common EOS reference, which the session-39 rule of paper_convergence.toml
called for). A part of reports/paper_study.py, read by its main."""
import math
import os
import statistics
from collections import defaultdict

from paper_rules import particle_rule, steady
from study import num, read_rows, strain_bin

COUPLED = ("demsph_stokes", "demsph_dd")


def one_window(rows, firsts, phi, points):
    """Session 34's one-window rule for the coupled models at Mn 1e-3, as it
    asked to be reported: each point's seed mean before it (each seed's
    short-window run if it has one, else its second run, else its entry: the
    runs session 33's tables used) against the entries now, and their windows."""
    earlier = defaultdict(dict)
    for f in firsts:
        earlier[(f["model"], int(f["seed"]))][f["run_number"]] = f
    lines = []
    for k in COUPLED:
        now = [r for r in rows if r["model"] == k and abs(float(r["mason"]) - 1e-3) < 1e-9]
        if not now:
            continue
        before = []
        for r in now:
            e = earlier[(k, int(r["seed"]))]
            before.append(e.get("w") or e.get(2) or r)
        def line(label, runs):
            vals = [num(x, "stress_total") for x in runs]
            wins = ", ".join(f"{num(x, 'warmup_strain'):g}-{num(x, 'strain'):g}" for x in runs)
            m, sd = statistics.mean(vals), (statistics.stdev(vals) if len(vals) > 1 else float("nan"))
            return (f"| {k} | {label} | {wins} | {m:.0f} ± {sd / math.sqrt(len(vals)):.0f} | "
                    f"{statistics.mean(num(x, 'stress_fluid') for x in runs):.0f} |")
        if not lines:
            lines = ["", "One window at Mn 1e-3 (session 34's rule, fixed before its runs): the coupled points' seed means "
                     "before it, in mixed windows, against their entries now (Pa; ± the seed scatter's standard error). "
                     "The rule's runs replace the 4-12 ones as they finish.", "",
                     "| model | runs | windows (strain) | total wall stress | fluid part |", "|---|---|---|---:|---:|"]
        lines += [line("session 33's", before), line("now", now)]
    return lines + window_bins([(r, points) for r in rows])


def window_bins(runs):
    """How far the one-window runs (16-48) still move inside their window: the
    total in 8-strain bins from each run's window_series.csv, and the second
    half's mean against the window's, in the run's own standard error. A
    description, not a test: the rule's verdict is the drift test's.
    runs: (sweep row, the archive that holds its run) pairs."""
    out = []
    for r, points in runs:
        if abs(float(r["mason"]) - 1e-3) > 1e-9 or (num(r, "warmup_strain"), num(r, "strain")) != (16.0, 48.0):
            continue
        path = os.path.join(points, r["model"], f"mn_{float(r['mason']):g}_seed_{int(r['seed'])}", "window_series.csv")
        if not os.path.exists(path):
            continue
        series = read_rows(path)
        whole, err = num(r, "stress_total"), num(r, "stress_total_err")
        late = strain_bin(series, "stress_total_Pa", 32, 48)
        out.append(f"| {r['model']} | {r.get('carrier', 'per_particle')} | {r['seed']} | {whole:.0f} ± {err:.0f} | "
                   + " | ".join(f"{strain_bin(series, 'stress_total_Pa', lo, lo + 8):.0f}" for lo in (16, 24, 32, 40))
                   + f" | {late:.0f} | {(late - whole) / err:+.1f} |")
    if not out:
        return []
    return ["", "Inside the one window (strain 16-48), each run's total wall stress in 8-strain bins (Pa, plain means "
            "of its window_series.csv) and the mean over the second half (32-48) against the window's, in the run's "
            "own standard error: how far the value still moves with the window's start. A description, not a "
            "test (the rule's verdict is the drift test above).", "",
            "| model | carrier | seed | 16-48 (the rule's) | 16-24 | 24-32 | 32-40 | 40-48 | 32-48 | "
            "(32-48) - (16-48), in its error |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"] + out


def seed_mean(runs):
    """The seed mean of the total wall stress (Pa) and its error by the
    convergence table's rule: max(the largest within-run error, SD / sqrt(n))."""
    vals = [num(r, "stress_total") for r in runs]
    sd = statistics.stdev(vals) if len(vals) > 1 else 0.0
    return statistics.mean(vals), max(max(num(r, "stress_total_err") for r in runs), sd / math.sqrt(len(vals)))


def rule_counts(runs):
    """The particle-part rule's verdicts on runs: how many pass, fail, or
    carry no version-2 estimate (untested)."""
    v = [particle_rule(r) for r in runs]
    ok, untested = v.count("ok"), v.count("untested")
    return ", ".join(f"{n} {w}" for n, w in ((ok, "pass"), (len(v) - ok - untested, "fail"), (untested, "untested")) if n)


def carrier_section(carrier, common_points):
    """The two carriers at Mn 1e-3 side by side (carrier: the rows of
    reports/study/paper/low_carrier.csv; common_points: the archive of the
    common-reference runs): each model's seed mean under each, the
    difference in combined errors, each run's steadiness, which one the
    headline holds, and the common runs' 8-strain bins."""
    if not any(r["carrier"] == "common" for r in carrier):
        return []
    lines = ["", "## The carrier at Mn 1e-3: per-particle against the common EOS reference", "",
             "The session-39 rule (experiments/sweeps/paper_convergence.toml, fixed before its rows were read) "
             "found model 3's common-reference row more than 2 combined standard errors above its per-particle base "
             "(reports/study/paper/convergence.md), so "
             "both coupled models' points at Mn 1e-3 run again with the common reference "
             "(experiments/sweeps/paper_common_low.toml: three seeds, strain 16-48, judged by the same tests, no "
             "further re-runs; seed 1 is the convergence row's run). The headline takes them once all six are "
             "in. Total wall stress in Pa; the error of a seed mean is the convergence table's: max(the largest "
             "within-run error, SD / sqrt(n)).", "",
             "| model | carrier | seeds | seed mean | error | fluid part | runs steady (both tests) | particle-part "
             "rule | in the headline |", "|---|---|---|---:|---:|---:|---:|---|---|"]
    diffs = []
    for k in COUPLED:
        means = {}
        for c in ("per_particle", "common"):
            runs = sorted((r for r in carrier if r["model"] == k and r["carrier"] == c), key=lambda r: int(r["seed"]))
            if not runs:
                continue
            means[c] = seed_mean(runs)
            fluid = statistics.mean(num(r, "stress_fluid") for r in runs)
            lines.append(f"| {k} | {c} | {', '.join(r['seed'] for r in runs)} | {means[c][0]:.0f} | "
                         f"{means[c][1]:.0f} | {fluid:.0f} | {sum(steady(r) for r in runs)} of {len(runs)} | "
                         f"{rule_counts(runs)} | {runs[0]['in_headline']} |")
        if len(means) == 2:
            (p, pe), (c, ce) = means["per_particle"], means["common"]
            diffs.append(f"{k} {100 * (c / p - 1):+.1f} % ({(c - p) / math.hypot(pe, ce):+.1f} combined errors)")
    if diffs:
        lines += ["", "Common against per-particle, seed mean against seed mean: " + "; ".join(diffs) + "."]
    return lines + window_bins([(r, common_points) for r in carrier if r["carrier"] == "common"])


