#!/usr/bin/python3
"""Issue 13's convergence table: how far the paper-scale stress moves with
each numerical choice (experiments/sweeps/paper_convergence.toml), against
the base, the three-seed means of the paper-scale sweep at the same model
and Mn (reports/study/paper/sweep.csv).

usage: paper_convergence.py CONVERGENCE_SWEEP_CSV [BASE_SWEEP_CSV] [OUT_MD]
  defaults: reports/study/paper/sweep.csv, reports/study/paper/convergence.md

Each variant is one seed. Its error is the larger of its within-run error
and the base's seed scatter (the standard deviation over the base's seeds:
a single seed of the variant scatters as a single seed of the base does);
the base's error is max(the largest within-run error of its seeds, seed
scatter / sqrt(n)). The shift is
quoted in per cent of the base and in combined standard errors. A variant
whose own run is not steady (drift |z| >= 3 or MSER-5 discard >= 0.2) is
marked: its shift is then not yet a measurement.

Beside it, a reading (not the table's rule): the shift in combined standard
errors with the seed standard deviation pooled over every seed set of the
same model and Mn that the repository holds, the base and the implicit-
tolerance ladders (reports/study/paper/tolerance*/points, one set per
tolerance), sqrt(sum (n_k - 1) s_k^2 / sum (n_k - 1)), in the place of the
base's own. A set of three seeds (2 degrees of freedom) can give a seed SD
far too small; the pooled one rests on more. The ladders' sets share their
seeds' starting states with each other (and the coupled ladder with the
base), so their degrees of freedom, which the column quotes, are an upper
bound.
"""
import csv
import glob
import json
import math
import os
import statistics
import sys
from collections import defaultdict

MU0 = 4e-7 * math.pi
DRIFT_Z, MSER_MAX = 3.0, 0.2


def rows(path):
    return [r for r in csv.DictReader(open(path)) if r["status"] == "ok"]


def f(r, k):
    try:
        return float(r[k])
    except (KeyError, ValueError):
        return float("nan")


def seed_sets(paper_dir):
    """(model, Mn) -> the seed sets of the tolerance ladders, one per archive
    and tolerance, each a list of (stress_total in Pa, magnetization)."""
    sets = defaultdict(list)
    for ladder in sorted(glob.glob(os.path.join(paper_dir, "tolerance*", "points"))):
        for tol in sorted(glob.glob(os.path.join(ladder, "*", "tol_*"))):
            by_mn = defaultdict(list)
            for path in sorted(glob.glob(os.path.join(tol, "mn_*_seed_*", "summary.json"))):
                with open(path) as fh:
                    sm = json.load(fh)
                mn = float(os.path.basename(os.path.dirname(path)).split("_")[1])
                by_mn[mn].append((sm["stress_total"], sm["magnetization"]))
            for mn, got in by_mn.items():
                sets[(os.path.basename(os.path.dirname(tol)), mn)].append(got)
    return sets


def pooled_sd(groups):
    """Pooled standard deviation and its degrees of freedom over groups of
    values (each group of at least 2)."""
    groups = [g for g in groups if len(g) > 1]
    dof = sum(len(g) - 1 for g in groups)
    if not dof:
        return float("nan"), 0
    return math.sqrt(sum((len(g) - 1) * statistics.variance(g) for g in groups) / dof), dof


def shift(r, base, sd_in=None):
    """A one-seed variant row r against its base's seed rows (same model and
    Mn), in units of the base's scale: (variant, its error, base mean, base
    error, sigma). Variant error: max(within-run, the base's seed SD); base
    error: max(the largest within-run error of its seeds, SD / sqrt(n)).
    sd_in: a seed SD (in the base's scale) to use in the place of the
    base's own."""
    phi = f(r, "volume_fraction")
    sc = (phi if phi == phi else 0.30) * MU0 * f(r, "magnetization") ** 2
    t, e = f(r, "stress_total") / sc, f(r, "stress_total_err") / sc
    bt = [f(x, "stress_total") / sc for x in base]
    within = max(f(x, "stress_total_err") for x in base) / sc
    sd = statistics.stdev(bt) if len(bt) > 1 else 0.0
    if sd_in is not None:
        sd = sd_in
    bm, be = statistics.mean(bt), max(within, sd / math.sqrt(len(bt)))
    ve = max(e, sd)
    return t, ve, bm, be, (t - bm) / math.hypot(be, ve)


def plot(bars, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = sorted({b[0] for b in bars})
    fig, axs = plt.subplots(1, len(groups), figsize=(3.2 * len(groups), 3.6), sharex=False)
    for ax, g in zip(axs if len(groups) > 1 else [axs], groups):
        mine = [b for b in bars if b[0] == g]
        for y, (_, v, sh, err, ok) in enumerate(mine):
            ax.errorbar([sh], [y], xerr=[err], fmt="o", mfc="C0" if ok else "none", color="C0", capsize=3)
        ax.axvline(0, color="k", lw=0.8)
        ax.set_yticks(range(len(mine)), [b[1] for b in mine], fontsize=7)
        ax.set_title(f"{g[0]}, Mn {g[1]:g}", fontsize=8)
        ax.set_xlabel("shift of the wall stress (%)", fontsize=7)
        ax.tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    here = os.path.dirname(os.path.abspath(__file__))
    conv = rows(argv[1])
    base_rows = rows(argv[2] if len(argv) > 2 else os.path.join(here, "study", "paper", "sweep.csv"))
    out = argv[3] if len(argv) > 3 else os.path.join(here, "study", "paper", "convergence.md")
    radii = [f(x, "radius") for x in base_rows if f(x, "radius") > 0]  # older summaries lack the radius
    for r in conv:
        if not f(r, "radius") > 0 and radii:
            r["radius"] = str(radii[0])

    def h_over_d(r):  # the SPH kernel over the particle diameter; 0 when unknown
        return f(r, "sph_h") / (2 * f(r, "radius")) if f(r, "sph_h") > 0 and f(r, "radius") > 0 else 0.0

    base = defaultdict(list)
    for r in base_rows:
        base[(r["model"], float(r["mason"]))].append(r)
    # the pooled seed SD per (model, Mn), in phi mu0 M^2: the base's seeds
    # and every tolerance ladder's set of the same point
    ladders = seed_sets(os.path.dirname(os.path.abspath(out)))
    pooled = {}
    for key, b in base.items():
        phi = f(b[0], "volume_fraction")
        phi = phi if phi == phi else 0.30
        groups = [[f(x, "stress_total") / (phi * MU0 * f(x, "magnetization") ** 2) for x in b]]
        groups += [[v / (phi * MU0 * m ** 2) for v, m in g] for g in ladders.get(key, [])]
        sd, dof = pooled_sd(groups)
        base_sd, base_dof = pooled_sd(groups[:1])
        pooled[key] = (sd, dof, len(groups) - 1, base_sd, base_dof)
    lines = ["# Convergence of the paper-scale stress (issue 13)", "",
             "experiments/sweeps/paper_convergence.toml: one numerical choice changed per variant, one seed, on the "
             "realistic path (1000 1/s, M from Mn) and the base's strain rules; written by reports/paper_convergence.py. "
             "Stress in phi mu0 M^2 (M the point's own). Base: the seed mean of reports/study/paper/sweep.csv at the "
             "same model and Mn, error max(the largest within-run error of its seeds, seed scatter / sqrt(n)) (more "
             "cautious than the report's stress table, which combines the within-run errors for the mean). Variant "
             "error: max(within-run, the base's seed standard deviation). Shift = variant / base - 1, and in "
             "combined standard errors. Where the base's seed scatter rests on 3 seeds (2 degrees of freedom) it can "
             "be far too small: model 3 at Mn 1 (the report's state note). Model 2 shares model 3's numerics (SPH, "
             "coupling, implicit contacts) and differs in the drag law only: it runs the two choices that move model "
             "3 most (gap, SPH spacing) and the carrier, and inherits model 3's rows for the others. Column "
             "'pooled': a reading, not the rule: the same shift with the seed SD pooled over the base and the "
             "implicit-tolerance ladders' seed sets of the same point (the table below it).", "",
             "| model | Mn | variant | wall stress | base (seeds) | shift | shift / sigma | pooled | particle part shift | "
             "variant steady | s per strain |", "|---|---:|---|---:|---:|---:|---:|---:|---:|---|---:|"]
    lever = {}  # (model, Mn) -> (|shift|, variant, shift, sigma, steady): the largest mover
    bars = []  # (model, Mn), variant, shift %, its combined error %, steady: the figure
    shifts = {}  # (model, Mn, variant) -> shift of the total and of the particle part (%)
    for r in sorted(conv, key=lambda r: (r["model"], float(r["mason"]), r["variant"])):
        key = (r["model"], float(r["mason"]))
        b = base.get(key, [])
        phi = f(r, "volume_fraction")
        sc = (phi if phi == phi else 0.30) * MU0 * f(r, "magnetization") ** 2
        t, e = f(r, "stress_total") / sc, f(r, "stress_total_err") / sc
        steady = abs(f(r, "stress_total_drift_z")) < DRIFT_Z and f(r, "steady_mser_discard_fraction") < MSER_MAX
        per = f(r, "wall_seconds") / f(r, "strain")
        if not b:
            lines.append(f"| {r['model']} | {key[1]:g} | {r['variant']} | {t:.5f} ± {e:.5f} | – | – | – | – | – | "
                         f"{'yes' if steady else '**no**'} | {per:.3g} |")
            continue
        _, ve, bm, be, z = shift(r, b)
        zp = shift(r, b, pooled[key][0])[4] if pooled[key][1] else float("nan")
        pm = statistics.mean([(f(x, "stress_total") - f(x, "stress_fluid")) / sc for x in b])
        vp = (f(r, "stress_total") - f(r, "stress_fluid")) / sc
        bars.append((key, r["variant"], 100 * (t / bm - 1), 100 * math.hypot(ve, be * t / bm) / bm, steady))
        shifts[(r["model"], key[1], r["variant"])] = (100 * (t / bm - 1), 100 * (vp / pm - 1))
        # the lever: the largest shift in standard errors among the variants
        # that are measurements (steady, and inside the coupling's validity)
        valid = not (r["variant"].startswith("sph_") and 0 < h_over_d(r) < 2)
        if steady and valid and abs(z) > lever.get(key, (-1,))[0]:
            lever[key] = (abs(z), r["variant"], t / bm - 1, z, steady)
        lines.append(f"| {r['model']} | {key[1]:g} | {r['variant']} | {t:.5f} ± {ve:.5f} | {bm:.5f} ± {be:.5f} "
                     f"({len(b)}) | {100 * (t / bm - 1):+.1f} % | {z:+.1f} | {zp:+.1f} | {100 * (vp / pm - 1):+.1f} % | "
                     f"{'yes' if steady else '**no**'} | {per:.3g} |")
    conv_keys = sorted({(r["model"], float(r["mason"])) for r in conv if (r["model"], float(r["mason"])) in pooled})
    if conv_keys:
        lines += ["", "The seed SD of each point (phi mu0 M^2): the base's own against the one pooled with the "
                  "tolerance ladders' sets (column 'pooled' above; degrees of freedom in brackets, an upper bound "
                  "where sets share their seeds' starting states):", "",
                  "| model | Mn | base seed SD (dof) | ladder sets | pooled seed SD (dof) | pooled / base |",
                  "|---|---:|---:|---:|---:|---:|"]
        for key in conv_keys:
            sd, dof, nsets, bsd, bdof = pooled[key]
            lines.append(f"| {key[0]} | {key[1]:g} | {bsd:.2e} ({bdof}) | {nsets} | {sd:.2e} ({dof}) | "
                         f"{sd / bsd if bsd > 0 else float('nan'):.2f} |")
    if lever:
        lines += ["", "The largest lever per model and Mn: the variant whose shift is largest in combined standard "
                  "errors, among those that are measurements (steady, and an SPH spacing the coupling admits):", ""]
        for (k, m), (_, v, sh, z, ok) in sorted(lever.items()):
            lines.append(f"- {k}, Mn {m:g}: {v}, {100 * sh:+.1f} % ({z:+.1f} sigma)")
    # SPH resolution: which spacings the unresolved, locally averaged
    # coupling admits (REFERENCE.md §6: the averaging assumes h >~ 2 d).
    res = sorted({(r["variant"], h_over_d(r)) for r in conv if r["variant"].startswith("sph_") and h_over_d(r) > 0})
    base_h = sorted({h_over_d(x) for x in base_rows if x["model"] != "dem_stokes" and h_over_d(x) > 0})
    if res:
        lines += ["", "SPH resolution against the coupling's validity (REFERENCE.md §6: the local averaging of the "
                  "unresolved coupling assumes a kernel of at least about 2 particle diameters, h/d >~ 2): "
                  + "; ".join(f"{v} h/d = {hd:.2f} ({'valid' if hd >= 2 else '**below 2: outside the model**'})"
                              for v, hd in res)
                  + (f"; the base h/d = {base_h[0]:.2f}." if base_h else ".")
                  + " A variant outside the model measures the discretisation, not the physics: its shift is "
                  "not a convergence error of the base."]
        # what the spacing moves: the total little, the split between the
        # SPH fluid part and the particle part (total - fluid part) much
        by_point = defaultdict(list)
        for (k, m, v), (tot, part) in shifts.items():
            if v.startswith("sph_"):
                by_point[(k, m)].append((float(v[4:].rstrip("um")), tot, part))
        if by_point:
            lines += ["", "What the spacing moves (shift of the total / of the particle part, by spacing; the base's "
                      "is 10 um): " + "; ".join(
                          f"{k} Mn {m:g}: " + ", ".join(f"{dx:g} um {tot:+.1f} % / {part:+.1f} %" for dx, tot, part
                                                        in sorted(v))
                          for (k, m), v in sorted(by_point.items()))
                      + f". The total moves by at most {max(abs(x[1]) for v in by_point.values() for x in v):.1f} %, "
                      f"the particle part by up to {max(abs(x[2]) for v in by_point.values() for x in v):.0f} %: "
                      "the carrier's kernel decides how much of the stress the SPH fluid carries and how much the "
                      "spheres do, so the particle part is a resolution-dependent split, and the total the better "
                      "converged quantity."]
    if bars:
        lines += ["", "![convergence](convergence.png)", "",
                  "The figure: each variant's shift of the wall stress from the base, in per cent, with its combined "
                  "standard error; hollow markers are variants whose own run is not steady."]
        plot(bars, os.path.join(os.path.dirname(os.path.abspath(out)), "convergence.png"))
    with open(out, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print(f"-> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
