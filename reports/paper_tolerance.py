#!/usr/bin/python3
"""The implicit tolerance on the paper cell: the rules fixed in advance.

Reads the runs of experiments/sweeps/paper_tolerance.toml (model 1),
paper_tolerance_coupled.toml (model 3) and experiments/branch_tolerance.txt
(model 1 at Mn 0.1, branches of one state per seed: scripts/branch-tolerance),
archived in reports/study/paper/tolerance/points, tolerance_coupled/points
and tolerance_branch/points (<model>/tol_<t>/mn_<Mn>_seed_<s>), and applies
the rule written in those files before any of their runs:
per Mn and tolerance t, the seed-by-seed difference of the wall stress
from the reference tolerance's run of the same seed, its mean b and
standard error SE; t passes at an Mn if |b| + 2 SE <= T, T half the median
within-run standard error of the reference runs; the chosen tolerance is
the loosest t that passes at every Mn with every tighter t passing too.
Beside it (not part of the decision): the observed order q of
|b(t)| = c t^q and the reference's residual bias c t_ref^q.

Writes reports/study/paper/tolerance.md and tolerance.png (both designs). A rule that
cannot be evaluated (a run missing, a seed without its reference run) is
reported as such, never filled in.

usage: reports/paper_tolerance.py [paper folder, default reports/study/paper] [--runs]
(--runs: the runs from out/sweeps/<sweep name>, as a sweep run without --archive leaves them)
"""
import json
import math
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DEFAULT = 1e-2


class Design:
    """One sweep of the rule: its name, archive folder under the paper folder, model, ladder (loosest
    first; the last is the reference), Mason numbers and seeds."""

    def __init__(self, sweep, archive, model, tols, mason, seeds, source=None):
        self.sweep, self.archive, self.model = sweep, archive, model
        self.tols, self.mason, self.seeds = tols, mason, seeds
        self.ref = tols[-1]
        self.source = source or f"experiments/sweeps/{sweep}.toml"  # where the design and its rule are written


DESIGNS = (
    Design("paper_tolerance", "tolerance/points", "dem_stokes", (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4), (1.0, 10.0),
           (1, 2, 3, 4, 5, 6)),
    Design("paper_tolerance_coupled", "tolerance_coupled/points", "demsph_dd", (1e-2, 2.5e-3, 6.25e-4), (1.0,),
           (1, 2, 3)),
    # branches of one state per seed (scripts/branch-tolerance): "seed" is the parent
    Design("branch_tolerance", "tolerance_branch/points", "dem_stokes", (1e-2, 2.5e-3, 6.25e-4), (0.1,),
           (1, 2, 3, 4, 5, 6), source="experiments/branch_tolerance.txt"),
)


def load(points, model, t, mn, seed):
    path = os.path.join(points, model, f"tol_{t:g}", f"mn_{mn:g}_seed_{seed}", "summary.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def steady(s):
    return abs(s["stress_total_drift_z"]) < 3 and s["steady_mser_discard_fraction"] < 0.2


def analyse(d, points):
    """runs[mn][t][seed] = summary or None; rows[mn][t] = the rule's numbers (b None where not computable);
    thresholds[mn] = T or None."""
    runs = {mn: {t: {s: load(points, d.model, t, mn, s) for s in d.seeds} for t in d.tols} for mn in d.mason}
    rows, thresholds = {}, {}
    for mn in d.mason:
        refs = runs[mn][d.ref]
        errs = [refs[s]["stress_total_err"] for s in d.seeds if refs[s]]
        thresholds[mn] = 0.5 * statistics.median(errs) if errs else None
        rows[mn] = {}
        for t in d.tols[:-1]:
            diff = [runs[mn][t][s]["stress_total"] - refs[s]["stress_total"] for s in d.seeds
                    if runs[mn][t][s] and refs[s]]
            if len(diff) < len(d.seeds):
                rows[mn][t] = {"n": len(diff), "b": None}
                continue
            b = statistics.fmean(diff)
            se = statistics.stdev(diff) / math.sqrt(len(diff))
            rows[mn][t] = {"n": len(diff), "b": b, "se": se, "bound": abs(b) + 2 * se,
                           "pass": abs(b) + 2 * se <= thresholds[mn]}
    return runs, rows, thresholds


def choose(d, rows):
    """The loosest t passing at every Mn with every tighter t (reference excepted) passing; 'incomplete'
    if a needed row is missing, 'inconclusive' if no t passes."""
    ladder = d.tols[:-1]
    if any(rows[mn][t]["b"] is None for mn in d.mason for t in ladder):
        return "incomplete"
    ok = [all(rows[mn][t]["pass"] for mn in d.mason) for t in ladder]
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


def section(d, runs, rows, thresholds, chosen, points):
    """The markdown of one design."""
    out = [f"## {d.model}: {d.source}", ""]
    if chosen == "incomplete":
        out += ["**Rule not yet evaluable**: runs are missing (below).", ""]
    elif chosen == "inconclusive":
        out += ["**Inconclusive**: no tolerance of the ladder passes at every Mn; by the rule nothing changes.", ""]
    else:
        verdict = "the default stays" if chosen >= DEFAULT else "tighter than the default: the rule's consequence applies"
        out += [f"**Chosen tolerance: {chosen:g}** ({verdict}).", ""]
    for mn in d.mason:
        out += [f"### Mn {mn:g}", "", f"T = {thresholds[mn]:.4f} Pa" if thresholds[mn] else "T: no reference runs yet",
                "", "| tolerance | seeds | b (Pa) | SE (Pa) | abs(b) + 2 SE | passes | seed mean (Pa) | seed SD | "
                "mean run error | mean steps | mean wall s | unsteady runs |",
                "|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---|"]
        for t in d.tols:
            have = [runs[mn][t][s] for s in d.seeds if runs[mn][t][s]]
            mean = statistics.fmean(r["stress_total"] for r in have) if have else float("nan")
            sd = statistics.stdev(r["stress_total"] for r in have) if len(have) > 1 else float("nan")
            err = statistics.fmean(r["stress_total_err"] for r in have) if have else float("nan")
            steps = statistics.fmean(r["steps"] for r in have) if have else float("nan")
            wall = statistics.fmean(r["wall_seconds"] for r in have) if have else float("nan")
            unsteady = ", ".join(str(s) for s in d.seeds if runs[mn][t][s] and not steady(runs[mn][t][s])) or "-"
            r = rows[mn].get(t)
            if t == d.ref:
                cells = ["(reference)", "", "", ""]
            elif r["b"] is None:
                cells = ["", "", "", "not yet"]
            else:
                cells = [f"{r['b']:+.4f}", f"{r['se']:.4f}", f"{r['bound']:.4f}", "yes" if r["pass"] else "**no**"]
            out.append(f"| {t:g} | {len(have)} | " + " | ".join(cells) + f" | {mean:.3f} | {sd:.3f} | {err:.3f} | "
                       f"{steps:.0f} | {wall:.0f} | {unsteady} |")
        out += ["", "The seed mean, seed SD and mean run error are shown beside the rule, not part of it."]
        fit = order_fit(rows, mn)
        if fit:
            q, c = fit
            out += ["", f"Observed order (not part of the rule): |b| = c t^q with q = {q:.2f}; the reference's own "
                        f"residual bias by it c {d.ref:g}^q = {c * d.ref ** q:.4f} Pa."]
        out += ["", "Per run (wall stress ± within-run error; * = not steady: drift |z| >= 3 or MSER-5 discard "
                    ">= 0.2):", "", "| seed | " + " | ".join(f"{t:g}" for t in d.tols) + " |",
                "|---:|" + "---:|" * len(d.tols)]
        for s in d.seeds:
            cells = ["" if not (r := runs[mn][t][s]) else
                     f"{r['stress_total']:.3f} ± {r['stress_total_err']:.3f}" + ("" if steady(r) else " *")
                     for t in d.tols]
            out.append(f"| {s} | " + " | ".join(cells) + " |")
        out.append("")
        out += block_table(d, points, mn)
    return out


def block_table(d, points, mn):
    """Where the runs keep blocks.csv (the branch design): each run's particle part in its 20-strain blocks,
    to show whether the branches of one parent stay in one state."""
    runs, edges = [], []
    for s in d.seeds:
        for t in d.tols:
            path = os.path.join(points, d.model, f"tol_{t:g}", f"mn_{mn:g}_seed_{s}", "blocks.csv")
            if os.path.exists(path):
                with open(path) as f:
                    blocks = [line.split(",") for line in f.read().splitlines()[1:]]
                edges = max(edges, [f"{b[0]}-{b[1]}" for b in blocks], key=len)
                runs.append((s, t, [float(b[2]) for b in blocks]))
    if not runs:
        return []
    return (["Particle part (Pa) of each branch in 20-strain blocks of its own strain, beside the rule:", "",
             "| parent | tolerance | " + " | ".join(edges) + " |", "|---:|---:|" + "---:|" * len(edges)] +
            [f"| {s} | {t:g} | " + " | ".join(f"{v:.2f}" for v in vals) + " |" * (1 + len(edges) - len(vals))
             for s, t, vals in runs] + [""])


def main():
    args = sys.argv[1:]
    from_runs = "--runs" in args
    args = [a for a in args if a != "--runs"]
    paper = args[0] if args else "reports/study/paper"
    out = ["# The implicit tolerance on the paper cell", "",
           "Rules and designs fixed before their runs (session 32, in each sweep file); written by "
           "reports/paper_tolerance.py. Wall stress in Pa; d = a run's stress minus the reference (finest) "
           "tolerance's run of the same seed; b = mean of d over the seeds, SE its standard error; T = half the "
           "median within-run error of the reference runs. A tolerance passes if |b| + 2 SE <= T; the chosen one "
           "is the loosest that passes at every Mn with every tighter one passing too.", ""]
    fig, ax = plt.subplots(figsize=(5.5, 4))
    colours = iter(("C0", "C1", "C2", "C3"))
    for d in DESIGNS:
        points = os.path.join("out", "sweeps", d.sweep) if from_runs else os.path.join(paper, d.archive)
        runs, rows, thresholds = analyse(d, points)
        chosen = choose(d, rows)
        out += section(d, runs, rows, thresholds, chosen, points)
        print(f"{d.sweep}: chosen {chosen}")
        for mn in d.mason:
            colour = next(colours)
            pts = [(t, r) for t, r in rows[mn].items() if r["b"] is not None]
            shift = 1.0 + 0.04 * (len(ax.lines) % 3)  # side by side, not on top of each other
            if pts:
                ax.errorbar([t * shift for t, _ in pts], [r["b"] for _, r in pts], yerr=[2 * r["se"] for _, r in pts],
                            fmt="o-", color=colour, capsize=3, label=f"{d.model} Mn {mn:g}: b ± 2 SE")
            if thresholds[mn]:
                for sign in (1, -1):
                    ax.axhline(sign * thresholds[mn], color=colour, ls="--", lw=1,
                               label=f"{d.model} Mn {mn:g}: ±T" if sign > 0 else None)
    out += ["![tolerance](tolerance.png)", "",
            "The figure: b against the tolerance with 2 SE bars, each point's ±T dashed; a tolerance passes "
            "where its whole bar lies between its ±T."]
    with open(os.path.join(paper, "tolerance.md"), "w") as f:
        f.write("\n".join(out) + "\n")
    ax.set_xscale("log")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("numerics.implicit_tol (fraction of R)")
    ax.set_ylabel("b: wall stress minus the finest tolerance's (Pa)")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(paper, "tolerance.png"), dpi=120)


if __name__ == "__main__":
    main()
