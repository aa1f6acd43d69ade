#!/usr/bin/python3
"""The implicit tolerance on the paper cell: the rule fixed in advance.

Reads the archived runs of experiments/sweeps/paper_tolerance.toml
(reports/study/paper/tolerance/points/dem_stokes/tol_<t>/mn_<Mn>_seed_<s>)
and applies the rule written in that file, before any of its runs:
per Mn and tolerance t, the seed-by-seed difference of the wall stress
from the reference tolerance's run of the same seed, its mean b and
standard error SE; t passes at an Mn if |b| + 2 SE <= T, T half the median
within-run standard error of the reference runs; the chosen tolerance is
the loosest t that passes at every Mn with every tighter t passing too.
Beside it (not part of the decision): the observed order q of
|b(t)| = c t^q and the reference's residual bias c t_ref^q.

Writes reports/study/paper/tolerance.md and tolerance.png. A rule that
cannot be evaluated (a run missing, a seed without its reference run) is
reported as such, never filled in.

usage: reports/paper_tolerance.py [paper folder, default reports/study/paper]
"""
import json
import math
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TOLS = (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4)  # the ladder, loosest first; the last is the reference
DEFAULT = 1e-2
MASON = (1.0, 10.0)
SEEDS = (1, 2, 3, 4, 5, 6)


def load(paper, t, mn, seed):
    path = os.path.join(paper, "tolerance", "points", "dem_stokes", f"tol_{t:g}", f"mn_{mn:g}_seed_{seed}",
                        "summary.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def steady(s):
    return abs(s["stress_total_drift_z"]) < 3 and s["steady_mser_discard_fraction"] < 0.2


def analyse(paper):
    """runs[mn][t][seed] = summary; rows[mn][t] = dict of the rule's numbers (None where not computable)."""
    runs = {mn: {t: {s: load(paper, t, mn, s) for s in SEEDS} for t in TOLS} for mn in MASON}
    ref = TOLS[-1]
    rows, thresholds = {}, {}
    for mn in MASON:
        refs = runs[mn][ref]
        have_ref = [s for s in SEEDS if refs[s]]
        thresholds[mn] = 0.5 * statistics.median([refs[s]["stress_total_err"] for s in have_ref]) if have_ref else None
        rows[mn] = {}
        for t in TOLS[:-1]:
            d = [runs[mn][t][s]["stress_total"] - refs[s]["stress_total"] for s in SEEDS
                 if runs[mn][t][s] and refs[s]]
            if len(d) < len(SEEDS):
                rows[mn][t] = {"n": len(d), "b": None}
                continue
            b = statistics.fmean(d)
            se = statistics.stdev(d) / math.sqrt(len(d))
            rows[mn][t] = {"n": len(d), "b": b, "se": se, "bound": abs(b) + 2 * se,
                           "pass": abs(b) + 2 * se <= thresholds[mn]}
    return runs, rows, thresholds


def choose(rows):
    """The loosest t passing at every Mn with every tighter t (reference excepted) passing; None if any
    needed row is missing ('incomplete'), or no t passes ('inconclusive')."""
    ladder = TOLS[:-1]
    if any(rows[mn][t]["b"] is None for mn in MASON for t in ladder):
        return "incomplete"
    ok = [all(rows[mn][t]["pass"] for mn in MASON) for t in ladder]
    for k, t in enumerate(ladder):
        if all(ok[k:]):
            return t
    return "inconclusive"


def order_fit(rows, mn):
    """q and c of |b| = c t^q over the ladder (least squares in logs), or None."""
    pts = [(math.log(t), math.log(abs(r["b"]))) for t, r in rows[mn].items() if r["b"] not in (None, 0.0)]
    if len(pts) < 3:
        return None
    mx = statistics.fmean(p[0] for p in pts)
    my = statistics.fmean(p[1] for p in pts)
    q = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
    return q, math.exp(my - q * mx)


def write(paper, runs, rows, thresholds, chosen):
    ref = TOLS[-1]
    out = ["# The implicit tolerance on the paper cell (model 1, Mn 1 and 10)", "",
           "experiments/sweeps/paper_tolerance.toml, rule and design fixed before its runs (session 32); "
           "written by reports/paper_tolerance.py. Wall stress in Pa; d = a run's stress minus the reference "
           f"tolerance's ({ref:g}) run of the same seed; b = mean of d over the seeds, SE its standard error; "
           "T = half the median within-run error of the reference runs. A tolerance passes if |b| + 2 SE <= T.", ""]
    if chosen == "incomplete":
        out += ["**Rule not yet evaluable**: runs are missing (below).", ""]
    elif chosen == "inconclusive":
        out += ["**Inconclusive**: no tolerance of the ladder passes at both Mn; by the rule nothing changes.", ""]
    else:
        verdict = "the default stays" if chosen >= DEFAULT else "tighter than the default: the consequence of the rule applies"
        out += [f"**Chosen tolerance: {chosen:g}** ({verdict}).", ""]
    for mn in MASON:
        fit = order_fit(rows, mn)
        out += [f"## Mn {mn:g}", "", f"T = {thresholds[mn]:.4f} Pa" if thresholds[mn] else "T: no reference runs yet", "",
                "| tolerance | seeds | b (Pa) | SE (Pa) | abs(b) + 2 SE | passes | mean steps | mean wall s | unsteady runs |",
                "|---:|---:|---:|---:|---:|---|---:|---:|---|"]
        for t in TOLS:
            have = [s for s in SEEDS if runs[mn][t][s]]
            steps = statistics.fmean(runs[mn][t][s]["steps"] for s in have) if have else float("nan")
            wall = statistics.fmean(runs[mn][t][s]["wall_seconds"] for s in have) if have else float("nan")
            unsteady = ", ".join(str(s) for s in have if not steady(runs[mn][t][s])) or "-"
            r = rows[mn].get(t)
            if t == ref:
                cells = ["(reference)", "", "", ""]
            elif r["b"] is None:
                cells = ["", "", "", "not yet"]
            else:
                cells = [f"{r['b']:+.4f}", f"{r['se']:.4f}", f"{r['bound']:.4f}", "yes" if r["pass"] else "**no**"]
            out.append(f"| {t:g} | {len(have)} | " + " | ".join(cells) + f" | {steps:.0f} | {wall:.0f} | {unsteady} |")
        if fit:
            q, c = fit
            out += ["", f"Observed order (not part of the rule): |b| = c t^q with q = {q:.2f}; the reference's own "
                        f"residual bias by it c {ref:g}^q = {c * ref ** q:.4f} Pa."]
        out += ["", "Per run (wall stress ± within-run error; * = not steady: drift |z| >= 3 or MSER-5 discard >= 0.2):", "",
                "| seed | " + " | ".join(f"{t:g}" for t in TOLS) + " |", "|---:|" + "---:|" * len(TOLS)]
        for s in SEEDS:
            cells = []
            for t in TOLS:
                r = runs[mn][t][s]
                cells.append("" if not r else f"{r['stress_total']:.3f} ± {r['stress_total_err']:.3f}"
                             + ("" if steady(r) else " *"))
            out.append(f"| {s} | " + " | ".join(cells) + " |")
        out.append("")
    out += ["![tolerance](tolerance.png)", "",
            "The figure: |b| against the tolerance with 2 SE bars, the threshold T of each Mn dashed."]
    with open(os.path.join(paper, "tolerance.md"), "w") as f:
        f.write("\n".join(out) + "\n")

    fig, ax = plt.subplots(figsize=(5.5, 4))
    for mn, colour in zip(MASON, ("C0", "C1")):
        pts = [(t, r) for t, r in rows[mn].items() if r["b"] is not None]
        if pts:
            ax.errorbar([t for t, _ in pts], [abs(r["b"]) for _, r in pts], yerr=[2 * r["se"] for _, r in pts],
                        fmt="o-", color=colour, capsize=3, label=f"Mn {mn:g}: |b| ± 2 SE")
        if thresholds[mn]:
            ax.axhline(thresholds[mn], color=colour, ls="--", lw=1, label=f"Mn {mn:g}: T")
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_xlabel("numerics.implicit_tol (fraction of R)")
    ax.set_ylabel(f"bias against tol {ref:g} (Pa)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(paper, "tolerance.png"), dpi=120)


def main():
    paper = sys.argv[1] if len(sys.argv) > 1 else "reports/study/paper"
    runs, rows, thresholds = analyse(paper)
    chosen = choose(rows)
    write(paper, runs, rows, thresholds, chosen)
    print("chosen:", chosen)


if __name__ == "__main__":
    main()
