#!/usr/bin/python3
"""The paper-scale study report (issue 13): the paper cell (150 x 50 x 120 um,
4125 spheres) on the realistic path (one shear rate, Mn set by the
magnetisation), the three models with seed-combined error bars, theory and
experiment on the same axes, the small-cell study beside it, steadiness of
every point, flow fits and cost per strain unit. Written for a sweep that is
still running: it reports what has finished and says what has not. The
rules it reads the runs by (steadiness, the particle-part rule, the claims,
the plateau, when the coupled values at Mn 1e-3 count) are in paper_rules.py.

usage: paper_study.py SWEEP_DIR OUT_DIR [--small reports/study/flow_curves.csv]
                      [--quasistatic reports/quasistatic/paper/results.csv]
                      [--fixed-m reports/study/paper/fixed_m_sweep.csv]
                      [--fixed-m-criterion reports/study/paper/fixed_m_criterion.json]
                      [--aqs-seeds headline_0.45,seed2,seed3]
                      [--first-runs reports/study/paper/first_runs]
                      [--second-runs reports/study/paper/second_runs]
                      [--short-window-runs reports/study/paper/short_window_runs] [--note TEXT]
                      [--points reports/study/paper/points]
                      [--small-criterion reports/study/criterion_default.json]
                      [--reanalysed reports/study/paper/reanalysed.json]
                      [--convergence reports/study/paper/convergence.md]
                      [--low-mn reports/study/paper/low_mn_sweep.csv]
                      [--low-long reports/study/paper/model1_low_long/sweep.csv]
                      [--transients reports/study/paper/transients.csv]
                      [--carrier reports/study/paper/low_carrier.csv]
                      [--common-points reports/study/paper/common_low/points]

The fixed-M path (experiments/sweeps/paper_fixed_m.toml, collected with
`mrf sweep ... --archive reports/study/paper/fixed_m_points --collect`, then
`mrf criterion` on it; its sweep.csv and criterion.json copied to the two
paths above), when it exists, is tabulated against the realistic path at
the same Mn, both seed-combined by mrf criterion.

The quasi-static (AQS, Mn -> 0) wall stress of the same cell, when its
results table exists (columns run, stress_over_phi_mu0_m2, err, note; one
row per AQS run), is drawn at the left edge of both panels and tabulated
beside the lowest-Mn particle stresses; the star is the value to quote, the
mean of the seed realisations named by --aqs-seeds (over their common
window) with the standard error of their scatter.

--first-runs, --second-runs: the summaries of the first and second runs of
points re-run for steadiness (reports/study/paper/first_runs/, second_runs/),
listed under the steadiness table with what their re-runs gave;
--short-window-runs: the coupled runs at Mn 1e-3 that session 34's
one-window rule runs again over strain 16-48 (each point's seed mean before
the rule against now is tabulated).
--points: the realistic sweep's point folders (archive layout), whose
window_series.csv give the one-window runs' totals in 8-strain bins.
--note: a paragraph under the title (what state the report is in).
--reanalysed: `mrf reanalyse` records of archived runs (scripts/paper_interim.py
writes them from the archive's window_series.csv files), for a post-hoc
reading of the particle-part rule on runs that carry the plain estimate.
--low-mn: model 1 at Mn 3e-4 (experiments/sweeps/paper_low_mn.toml, collected
from reports/study/paper/low_mn_points by scripts/paper_interim.py), read
by the rule that sweep file fixed before its runs.
--low-long, --transients: model 1's long windows at Mn 3e-4 and 1e-3
(experiments/sweeps/paper_model1_low_long.toml, collected by
scripts/paper_interim.py) and the binned whole runs that its first question
reads (reports/paper_transients.py), read by the rule that sweep file fixed.
--carrier: the coupled runs at Mn 1e-3 under the per-particle carrier and
the common EOS reference (scripts/paper_interim.py writes it; columns
carrier and in_headline), tabulated side by side (reports/paper_carrier.py);
--common-points: the archive of the common-reference runs (their bins).
--convergence: the convergence table (reports/paper_convergence.py), whose
largest-lever lines the opening section repeats.
--small-criterion: mrf criterion's output for the small-cell study, whose
claims are re-measured on the paper cell (deviations from model 3, model 1's
volume-side stress, the slope of the flow curve at the lowest Mn).

SWEEP_DIR holds sweep.csv (mrf sweep ... --collect) and criterion.json
(mrf criterion SWEEP_DIR). Writes OUT_DIR/paper.md and its figures.
"""
import json
import math
import os
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paper_carrier import carrier_section, one_window  # noqa: E402
from paper_rules import (DRIFT_Z, MIN_INDEPENDENT, MSER_MAX, arg, coupled_open_at, fe, low_long,  # noqa: E402
                         low_long_rows, low_mn, low_mn_rows, lowest_slopes, mkey, old_claims, particle_note,
                         particle_rule, particle_state, seed_combined, slope_status, steady)
from study import (CHAIN_YIELD, COLOR, GINDER_SAT, LABEL, MN_CONVENTION, MU0, ORDER,  # noqa: E402
                   experiment_points, num, read_rows, save)


def post_hoc(argv, here, rows):
    """The particle-part rule read post hoc on the archived runs that carry the
    plain estimate but kept their window series (scripts/paper_interim.py:
    reanalysed.json, `mrf reanalyse` of each): (model, Mn, seed) -> verdict.
    These runs were seen before the rule was written, so this is not a test
    of it."""
    path = arg(argv, "--reanalysed", os.path.join(here, "study", "paper", "reanalysed.json"))
    if not os.path.exists(path):
        return {}
    strain = {(r["model"], mkey(r["mason"]), int(r["seed"])): num(r, "strain") for r in rows}
    out = {}
    for q in json.load(open(path)):
        key = (q["model"], mkey(q["mason"]), int(q["seed"]))
        if q.get("stored_error_estimate_version", 1) >= 2 or strain.get(key) != q["strain"]:
            continue  # judged by the rule itself, or another run than the table's
        out[key] = particle_rule({"error_estimate_version": 2,
                                  "stress_particles_drift_z": q["stress_particles"]["drift_z"],
                                  "stress_particles_independent_samples": q["stress_particles"]["independent_samples"],
                                  "stress_total_independent_samples": q["stress_total"]["independent_samples"]})
    return out


def two_paths(argv, here, crit, phi, models):
    """Issue 13's second path: the same cell at a fixed M = 1 MA/m, Mn set by
    the shear rate (experiments/sweeps/paper_fixed_m.toml), against the
    realistic path at the same Mn."""
    path = arg(argv, "--fixed-m", os.path.join(here, "study", "paper", "fixed_m_sweep.csv"))
    crit_path = arg(argv, "--fixed-m-criterion", os.path.join(here, "study", "paper", "fixed_m_criterion.json"))
    if not (os.path.exists(path) and os.path.exists(crit_path)):
        return []
    fixed = json.load(open(crit_path))  # the seed-combined points, as for the realistic path
    dimless = {}  # St and Re_p of each (model, Mn), from the runs
    unsteady = defaultdict(int)  # runs failing a steadiness test, per (model, Mn)
    fixed_rows = [r for r in read_rows(path) if r["status"] == "ok"]
    pstate = particle_state(fixed_rows)
    for r in fixed_rows:
        dimless[(r["model"], float(r["mason"]))] = (num(r, "stokes_number"), num(r, "reynolds_number"))
        unsteady[(r["model"], float(r["mason"]))] += 0 if steady(r) else 1
    lines = ["## Two paths to a Mason number", "",
             "The realistic path (gdot = 1e3 1/s, M set by Mn: St and Re_p about 1e-4) against a fixed "
             "M = 1 MA/m with Mn set by the shear rate (experiments/sweeps/paper_fixed_m.toml: St = 0.30 Mn, "
             "Re_p = 0.175 Mn). Total wall stress / (phi mu0 M^2), seed-combined by mrf criterion as the "
             "realistic path is; the difference in combined standard errors. Where it is large, the model's "
             "behaviour at that Mn on the fixed-M path is inertia, not rheology. Seeds: how many, and in brackets "
             "how many of them fail a steadiness test (after their one re-run, experiments/sweeps/paper_fixed_m.toml); "
             "after the fixed-M particle part, how many runs fail the particle-part rule or predate it (steadiness "
             "section).", "",
             "| model | Mn | seeds (fixed M) | fixed M | St, Re_p | realistic | fixed - realistic (sigma) | "
             "particle part: fixed M | realistic |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    real = {(k, q["mason"]): q for k in models for q in crit["models"][k]["points"]}
    for k in [m for m in ORDER if m in fixed["models"]]:
        for f in sorted(fixed["models"][k]["points"], key=lambda q: q["mason"]):
            sc = phi * MU0 * f["magnetization"] ** 2
            t, e = f["stress"] / sc, f["err"] / sc
            pt = (f["stress"] - f["stress_fluid"]) / sc
            st, re = dimless.get((k, f["mason"]), (float("nan"), float("nan")))
            q = real.get((k, f["mason"]))
            pnote = particle_note(pstate.get((k, mkey(f["mason"]))))
            if q:
                sr = phi * MU0 * q["magnetization"] ** 2
                rt, re_ = q["stress"] / sr, q["err"] / sr
                cmp_ = (f"{rt:.4f} ± {fe(re_)} | {(t - rt) / math.hypot(e, re_):+.1f} | {pt:.4f} ± {fe(e)}{pnote} | "
                        f"{(q['stress'] - q['stress_fluid']) / sr:.4f} ± {fe(re_)}")
            else:
                cmp_ = f"– | – | {pt:.4f} ± {fe(e)}{pnote} | –"
            bad = unsteady.get((k, f["mason"]), 0)
            seeds = f"{f['seeds']}" + (f" ({bad} unsteady)" if bad else "")
            lines.append(f"| {k} | {f['mason']:g} | {seeds} | {t:.4f} ± {fe(e)} | {st:.2g}, {re:.2g} | {cmp_} |")
    lines.append("")
    return lines


def against_small(q, small_k, phi, small_m):
    """A seed-combined paper-cell point in phi mu0 M^2 (value, error) and the
    two table cells that set it against the small cell at the same Mn
    (its value, the difference in combined standard errors)."""
    sc = phi * MU0 * q["magnetization"] ** 2
    t, e = q["stress"] / sc, q["err"] / sc
    sm = small_k.get(q["mason"])
    if not sm:
        return t, e, "– | –"
    ss = phi * MU0 * small_m ** 2
    st, se = sm[0] / ss, sm[1] / ss
    return t, e, f"{st:.4f} ± {fe(se)} | {(t - st) / math.hypot(e, se):+.1f}"


def answers(crit, small, phi, small_m, pstate, unsteady, claim_lines, cost_line, conv_path, extra=(), swapped=False):
    """The section a reader wants first: the three models' stress at Mn 1e-2
    and 1 on the paper cell and the small cell, how settled each number is,
    the largest numerical lever (the convergence table), what the whole sweep
    cost and which of the small-cell study's claims survive. Every number is
    the one a later section derives; this only gathers them."""
    lines = ["## The answers so far", "",
             "Gathered from the sections below (nothing here is computed only here). Stress / (phi mu0 M^2), "
             "seed-combined, error = max(within-run, seed scatter / sqrt(n)); 'runs not steady': runs of the "
             "point that fail the drift or MSER-5 test (after their re-run, or the first run while the re-run is "
             "pending: the steadiness section lists them); 'particle part': how many runs pass "
             "the session-25 particle-part rule, fail it, or predate it (untested). Where the seed scatter sets "
             "the error (most coupled points: the stress table's ratio column), it rests on 3 seeds, 2 degrees of "
             "freedom: a 95 % interval is then 4.3 standard errors wide each side (Student's t), so a difference of "
             "2-4 sigma is suggestive, not established.", "",
             "The small cell ran at fixed M, the paper cell on the realistic path, so 'paper - small' holds the "
             "path as well as the box (stress table).", "",
             "| model | Mn | paper cell | small cell | paper - small (sigma) | runs not steady | particle part |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for m in (1e-2, 1.0):
        for k in [x for x in ORDER if x in crit["models"]]:
            q = next((q for q in crit["models"][k]["points"] if mkey(q["mason"]) == mkey(m)), None)
            if q is None:
                continue
            t, e, cmp_ = against_small(q, small[k], phi, small_m)
            c = pstate.get((k, mkey(m)), [0, 0, 0])
            part = f"{c[2] - c[0] - c[1]} pass, {c[0]} fail, {c[1]} untested"
            lines.append(f"| {k} | {m:g} | {t:.4f} ± {fe(e)} | {cmp_} | {unsteady.get((k, mkey(m)), 0)} of "
                         f"{q['seeds']} | {part} |")
    lines.append("")
    if os.path.exists(conv_path):
        conv = open(conv_path).read()
        lever = [x[2:] for x in conv.split("The largest lever per model and Mn")[-1].split("\n\n")[1].splitlines()
                 if x.startswith("- ")] if "The largest lever per model and Mn" in conv else []
        if lever:
            lines += ["The largest numerical lever (reports/study/paper/convergence.md, one seed per variant, "
                      "still filling in): " + "; ".join(lever) + "." + (
                          " The convergence table's base is the headline with the per-particle carrier; at Mn 1e-3 "
                          "the headline now takes the common-reference runs, so the eos_common_low rows there "
                          "measure what that swap changed, not a lever of the headline." if swapped else ""), ""]
    verdicts = defaultdict(lambda: [0, 0])
    for x in claim_lines:
        cells = [c.strip() for c in x.strip("|").split("|")]
        if len(cells) == 5 and cells[4] in ("yes", "**no**"):
            verdicts[cells[0]][cells[4] != "yes"] += 1
    if verdicts:
        lines += ["The small-cell study's claims on the paper cell (holds at how many of the Mn tested; the claims "
                  "section below has each value):", ""]
        lines += [f"- {claim}: holds at {v[0]} of {v[0] + v[1]}" for claim, v in verdicts.items()]
        flat = [[c.strip() for c in x.strip("|").split("|")] for x in claim_lines if "| paper | " in x]
        if flat:
            lines.append("- no yield plateau down to Mn = 1e-3: the paper cell's particle part between the two "
                         "lowest Mn is " + "; ".join(f"{c[0]} s = {c[4]}, "
                                                     f"{ {'yes': 'flat', 'no': 'not flat'}.get(c[6], c[6])}"
                                                     for c in flat))
        lines.append("")
    for x in extra:
        lines += [x, ""]
    lines += [cost_line, ""]
    return lines


def theory_and_experiment(crit, phi, expt, aqs_quote):
    """The low-Mn stress scales of the three models beside the point-dipole
    chain model, Ginder's saturation value and the measured yield stresses
    (experiments/data), all in phi mu0 M^2, with the ratio of each measured
    range to the models' lowest-Mn particle stress."""
    lines = ["## Against theory and experiment", "",
             "All in phi mu0 M^2. Simulation: the particle part at the lowest Mn (the dynamic stress the magnetic "
             "structure carries; the carrier's eta gdot removed) and the Bingham fit's dynamic yield stress "
             "(flow-curve section), and the quasi-static (AQS) limit; theory: the ideal point-dipole chain at its "
             "optimal tilt (REFERENCE.md TEST 1.5) and Ginder, Davis & Elie's saturation value for saturated "
             "spheres (finite elements, Ms = M); experiment: the yield stresses of experiments/data "
             "(MRF-132DG-class fluids near phi 0.3, tau_y with M from the fluids' B-H curves; sources and caveats in "
             "its README).", "",
             "| what | tau / (phi mu0 M^2) |", "|---|---:|"]
    lows, above = [], []
    for k in [x for x in ORDER if x in crit["models"]]:
        p = sorted(crit["models"][k]["points"], key=lambda q: q["mason"])
        if not p:
            continue
        q = p[0]
        sc = phi * MU0 * q["magnetization"] ** 2
        v = (q["stress"] - q["stress_fluid"]) / sc
        lows.append(v)
        lines.append(f"| {LABEL[k]}: particle part at Mn {q['mason']:g} | {v:.4f} ± {q['err'] / sc:.4f} |")
        b = crit["models"][k].get("bingham", {})
        if b.get("ok") and "slope" in b:
            ty = b["slope"] / (4.5 * phi)
            lines.append(f"| {LABEL[k]}: Bingham dynamic yield stress | {ty:.4f} ± "
                         f"{b['slope_err'] / (4.5 * phi):.4f} |")
            if ty > 1.5 * v:
                above.append(f"{LABEL[k]} {ty / v:.1f}x")
    if math.isfinite(aqs_quote[0]):
        lines.append(f"| quasi-static limit (AQS, model 1's forces, mean of {aqs_quote[2]} seeds) | "
                     f"{aqs_quote[0]:.4f} ± {aqs_quote[1]:.4f} |")
    lines += [f"| ideal point-dipole chain, optimal tilt | {CHAIN_YIELD:.4f} |",
              f"| Ginder saturation (Ms = M) | {GINDER_SAT:.4f} |"]
    by_src = defaultdict(list)
    for src, _, v in expt:
        by_src[src].append(v)
    for src, vs in sorted(by_src.items()):
        kind = "empirical fit (not a measurement)" if src.endswith("_FIT") else "experiment"
        lines.append(f"| {kind} {src} ({len(vs)} fields) | {min(vs):.3f} - {max(vs):.3f} |")
    lines.append("")
    if lows and by_src:
        allv = [v for vs in by_src.values() for v in vs]
        lo, hi = min(allv) / max(lows), max(allv) / min(lows)
        def span(a, b):
            return f"{a:.0f}-{b:.0f}" if round(a) != round(b) else f"about {a:.0f}"

        lines += [f"The measured (and fitted) yield stresses are {span(lo, hi)} times the models' particle stress at the "
                  f"lowest Mn, and the ideal chain {span(CHAIN_YIELD / max(lows), CHAIN_YIELD / min(lows))} "
                  "times. The three drag models differ among themselves far less than any of them differs from the "
                  "measurements: the gap is the magnetic model, not the hydrodynamics. The spheres carry fixed point "
                  "dipoles without mutual induction (REFERENCE.md §1), while in iron the field concentrates in the "
                  "gaps of touching spheres and the contact attraction is much stronger; and the random, "
                  "sheared structure carries less stress than ideal chains at their optimal tilt. What mrf can "
                  "answer is how the drag model changes the stress of this magnetic model, which is the study's "
                  "question; it does not predict a real fluid's yield stress.", ""]
    if above:
        lines += ["The Bingham fit's yield stress lies above the particle stress the same model carries at the "
                  "lowest Mn (" + ", ".join(above) + "): the fit (chi2/dof far above 1, flow-curve section) "
                  "extrapolates the curvature of the higher Mn, it is no measured yield stress; the particle part at "
                  "the lowest Mn is the figure to compare.", ""]
    return lines


def sweep_cost(rows, firsts, beside=()):
    """The wall time of the whole sweep: every run that counts, plus the
    first runs (summaries) that the steadiness re-runs replaced and the
    runs of the carrier the headline does not hold (`beside`)."""
    per = defaultdict(float)
    for r in rows:
        per[r["model"]] += num(r, "wall_seconds")
    current = {(r["model"], float(r["mason"]), int(r["seed"])): num(r, "strain") for r in rows}
    # an earlier run counts only once a re-run (another strain) has replaced it
    firsts = [f for f in firsts if current.get((f["model"], float(f["mason"]), int(f["seed"]))) not in (None, f["strain"])]
    first = sum(f.get("wall_seconds", 0.0) for f in firsts)
    other = sum(num(r, "wall_seconds") for r in beside)
    total = sum(per.values()) + first + other
    timed = [r for r in rows if num(r, "cpu_seconds") > 0]  # runs of checkpoint format 10 on record their CPU time
    cpu = (f" CPU time, which leaves out pauses and the other jobs on the cores, is on record for {len(timed)} of the "
           f"runs counted: {sum(num(r, 'cpu_seconds') for r in timed) / 3600:.2f} core-hours against their "
           f"{sum(num(r, 'wall_seconds') for r in timed) / 3600:.2f} h of wall time." if timed else "")
    return ["Whole-sweep wall time (one thread per run, summed over runs; shared machine, an upper bound): "
            + ", ".join(f"{k} {per[k] / 3600:.1f} h" for k in ORDER if k in per)
            + f", the earlier runs replaced by re-runs {first / 3600:.1f} h"
            + (f", the other carrier's runs at Mn 1e-3 {other / 3600:.1f} h" if beside else "")
            + f"; **{total / 3600:.1f} core-hours** in all ({len(rows)} runs counted, {len(firsts)} replaced"
            + (f", {len(beside)} beside" if beside else "") + ")." + cpu, ""]


class Study:
    """What every section of the report reads: the runs, mrf criterion's
    points, the small cell, the quasi-static values and the command line."""

    def __init__(self, argv):
        self.argv = argv
        self.sweep_dir, self.out = argv[1], argv[2]
        self.here = here = os.path.dirname(os.path.abspath(__file__))
        self.rows = [r for r in read_rows(os.path.join(self.sweep_dir, "sweep.csv")) if r["status"] == "ok"]
        # the coupled runs at Mn 1e-3 under both carriers (scripts/paper_interim.py's carrier_swap)
        carrier_path = arg(argv, "--carrier", os.path.join(here, "study", "paper", "low_carrier.csv"))
        self.carrier = ([r for r in read_rows(carrier_path) if r["status"] == "ok"]
                        if os.path.exists(carrier_path) else [])
        self.crit = json.load(open(os.path.join(self.sweep_dir, "criterion.json")))
        self.phi = self.crit["volume_fraction"]
        self.models = [k for k in ORDER if k in self.crit["models"]]
        self.expt = experiment_points(os.path.join(here, "..", "experiments", "data", "experiment_mrf.csv"))
        self.small = defaultdict(dict)
        small_path = arg(argv, "--small", os.path.join(here, "study", "flow_curves.csv"))
        if os.path.exists(small_path):
            for r in read_rows(small_path):
                self.small[r["model"]][float(r["mason"])] = (num(r, "stress_Pa"), num(r, "err_Pa"))
        qs_path = arg(argv, "--quasistatic", os.path.join(here, "quasistatic", "paper", "results.csv"))
        self.qs = list(read_rows(qs_path)) if os.path.exists(qs_path) else []
        # The AQS value to quote: the mean of the seed realisations over their
        # common window, its error the standard error of their scatter
        # (reports/quasistatic/README.md §5); --aqs-seeds names the runs.
        self.seed_runs = arg(argv, "--aqs-seeds", "headline_0.45,seed2,seed3").split(",")
        seed_vals = [num(r, "stress_over_phi_mu0_m2") for r in self.qs if r["run"] in self.seed_runs]
        self.aqs_quote = ((statistics.mean(seed_vals), statistics.stdev(seed_vals) / math.sqrt(len(seed_vals)),
                           len(seed_vals)) if len(seed_vals) >= 2 else (float("nan"), float("nan"), len(seed_vals)))
        self.small_m = 1e6  # the small-cell study's fixed magnetisation (experiments/sweeps/default.toml)
        self.gdot = num(self.rows[0], "shear_rate") if self.rows else float("nan")
        self.grid = [1e-3, 1e-2, 0.1, 1.0, 10.0]
        self.low_rows = low_mn_rows(argv, here)  # model 1 below Mn 1e-3
        # the long runs' binned transients (reports/paper_transients.py)
        self.transients = arg(argv, "--transients", os.path.join(here, "study", "paper", "transients.csv"))
        self.by = defaultdict(list)  # (model, Mn) -> its runs
        for r in self.rows:
            self.by[(r["model"], float(r["mason"]))].append(r)


def stress_figure(st):
    """stress_vs_mason: the total and the particle part against Mn, the small
    cell, model 1 below Mn 1e-3, the quasi-static value, theory and
    experiment."""
    crit, phi, small, small_m, low_rows, qs, aqs_quote = st.crit, st.phi, st.small, st.small_m, st.low_rows, st.qs, \
        st.aqs_quote
    models, expt, gdot, out = st.models, st.expt, st.gdot, st.out
    fig, axs = plt.subplots(1, 2, figsize=(13, 5))
    for k in models:
        p = crit["models"][k]["points"]
        s = [phi * MU0 * q["magnetization"] ** 2 for q in p]
        x = [q["mason"] for q in p]
        axs[0].errorbar(x, [q["stress"] / si for q, si in zip(p, s)], yerr=[q["err"] / si for q, si in zip(p, s)],
                        fmt="o-", ms=4, capsize=3, color=COLOR[k], label=LABEL[k] + " (paper cell)")
        axs[1].errorbar(x, [(q["stress"] - q["stress_fluid"]) / si for q, si in zip(p, s)],
                        yerr=[q["err"] / si for q, si in zip(p, s)], fmt="o-", ms=4, capsize=3, color=COLOR[k],
                        label=LABEL[k] + " (paper cell)")
        if small[k]:
            xs = sorted(small[k])
            axs[0].errorbar(xs, [small[k][m][0] / (phi * MU0 * small_m ** 2) for m in xs],
                            yerr=[small[k][m][1] / (phi * MU0 * small_m ** 2) for m in xs], fmt="x:", ms=4,
                            capsize=2, color=COLOR[k], alpha=0.6, label=LABEL[k] + " (small cell, fixed M)")
    if low_rows:  # model 1 below Mn 1e-3 (its section)
        for ax, particle_part in ((axs[0], False), (axs[1], True)):
            mean, err, _, _ = seed_combined(low_rows, phi, particle_part)
            ax.errorbar([num(low_rows[0], "mason")], [mean], yerr=[err], fmt="D", mfc="none", ms=5, capsize=3,
                        color=COLOR["dem_stokes"], label=f"{LABEL['dem_stokes']} below Mn 1e-3 ({len(low_rows)} seeds)")
    for ax in axs:
        if qs:  # the quoted AQS value (mean of the seeds) at the left edge, every run as its spread
            v, e, n_seeds = aqs_quote
            ax.errorbar([1.6e-4], [v], yerr=[e], fmt="*", ms=10, color="k", capsize=3,
                        label=f"quasi-static (AQS, Mn -> 0): mean of {n_seeds} seeds")
            others = [num(r, "stress_over_phi_mu0_m2") for r in qs]
            if others:
                ax.plot([1.6e-4] * len(others), others, "k.", ms=4, alpha=0.5, label="AQS variants (increment, tol, "
                        "cut-off, seed, Y)")
        ax.axhline(CHAIN_YIELD, color="k", ls="--", lw=1, label="chain model yield 0.137")
        ax.axhline(GINDER_SAT, color="gray", ls=":", lw=1, label="Ginder saturation 0.086 (Ms = M)")
        sources = sorted({e[0] for e in expt})
        for src in sources:
            vals = [v for s_, _, v in expt if s_ == src]
            ax.plot([1.2e-4] * len(vals), vals, marker="s^vD<>"[sources.index(src) % 6], color="tab:red", ms=5,
                    ls="none", label=f"experiment {src} (yield stress)")
        ax.set(xscale="log", yscale="log", xlabel=f"Mason number ({MN_CONVENTION})", xlim=(1e-4, 20))
    axs[0].set(ylabel="wall shear stress / (phi mu0 M^2)", title="total (particles + carrier)")
    axs[1].set(ylabel="(stress - fluid part) / (phi mu0 M^2)", title="particle part: tau - tau_fluid")
    axs[0].legend(fontsize=6)
    fig.text(0.01, -0.02, f"{MN_CONVENTION}; paper cell at gdot = {gdot:g} 1/s, M = sqrt(9 eta gdot/(2 mu0 Mn)); "
             f"phi = {phi:.2f}; error bars: max(within-run, seed scatter / sqrt(n)); experiment drawn at the left edge",
             fontsize=7)
    save(fig, out, "stress_vs_mason")


def opening_tables(st):
    """The title, the state note, the progress table and the stress per point."""
    rows, crit, phi, models, small, small_m, gdot, grid, argv = st.rows, st.crit, st.phi, st.models, st.small, \
        st.small_m, st.gdot, st.grid, st.argv
    lines = ["# The paper-scale study (issue 13)", "",
             f"Paper cell (150 x 50 x 120 um, {int(num(rows[0], 'n_particles')) if rows else 0} spheres, dipole "
             f"cut-off 4 d, Y = 200 GPa) on the realistic path: gdot = {gdot:g} 1/s for every point, "
             "M = sqrt(9 eta gdot / (2 mu0 Mn)) (REFERENCE.md §8). Sweep: experiments/sweeps/paper_realistic.toml; "
             "finished points are archived in reports/study/paper/points/ (mrf sweep --archive).", ""]
    if "--note" in argv:
        lines += [arg(argv, "--note", ""), ""]
    lines += ["![stress](stress_vs_mason.png)", ""]
    done = defaultdict(int)
    for r in rows:
        done[(r["model"], float(r["mason"]))] += 1
    lines += ["## Progress: finished seeds per point (of 3)", "", "| model | " + " | ".join(f"Mn {m:g}" for m in grid)
              + " |", "|---|" + "---:|" * len(grid)]
    for k in ORDER:
        lines.append(f"| {k} | " + " | ".join(str(done[(k, m)]) for m in grid) + " |")
    lines += ["", "## Stress per point (seed-combined)", "",
              "stress/(phi mu0 M^2) with M the point's own; err = max(within-run, seed scatter/sqrt(n)) (a point of "
              "one seed has its within-run error only, which the seed scatter of this cell exceeds several "
              "times where it is known: read it as a lower bound); "
              "particle part = total - fluid part (model 1: eta gdot exactly). Small cell: the default study "
              "(375 spheres, fixed M = 1e6 A/m), same Mn; difference in combined standard errors. The two cells "
              "differ in path as well as in size: at Mn >= 0.1 the path alone moves the paper cell's stress beyond "
              "its error bars (section \"Two paths to a Mason number\"), so there the difference is not the "
              "box's. Ratio column: seed scatter / sqrt(n) against the runs' combined within-run error, "
              "both errors of the mean (above 1 the seed scatter sets the error).", "",
              "| model | Mn | seeds | total | particle part | seed scatter / within-run | small cell total | "
              "paper - small (sigma) |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    pstate = particle_state(rows)
    for k in models:
        for q in crit["models"][k]["points"]:
            s = phi * MU0 * q["magnetization"] ** 2
            t, e, cmp_ = against_small(q, small[k], phi, small_m)
            # both as errors of the mean (criterion.json: seed_scatter is the
            # seeds' SD, within_err the runs' errors combined for the mean)
            ratio = (q["seed_scatter"] / math.sqrt(q["seeds"]) / q["within_err"]
                     if q["within_err"] > 0 and q["seeds"] > 1 else float("nan"))
            ef = fe(e)
            rf = "– (one seed: no scatter)" if math.isnan(ratio) else f"{ratio:.2f}"
            lines.append(f"| {k} | {q['mason']:g} | {q['seeds']} | {t:.4f} ± {ef} | "
                         f"{(q['stress'] - q['stress_fluid']) / s:.4f} ± {ef}{particle_note(pstate.get((k, mkey(q['mason']))))} | "
                         f"{rf} | {cmp_} |")
    return lines


def steadiness(st):
    """The steadiness of every run, the post-hoc readings and the earlier
    runs of points re-run for steadiness; returns the lines and those runs."""
    rows, argv, here = st.rows, st.argv, st.here
    newer = sum(1 for r in rows if num(r, "error_estimate_version") >= 2)
    lines = ["", f"## Steadiness of every run (drift |z| < {DRIFT_Z:g} and MSER-5 discard < {MSER_MAX:g})", "",
              f"Error estimate: {newer} of {len(rows)} runs carry the block error widened by the blocks' residual "
              "correlation, with the drift test on detrended halves (`error_estimate_version` 2, from session 24); "
              "the others the plain Jonsson level, whose errors are too small and whose drift test flags too often "
              "when a window holds few correlation times (docs/study.md, \"Error bars with few correlation "
              "times\": on the 19 runs whose series could be re-analysed, errors 1.0-2.6x larger and 3 of 5 "
              "drift flags cleared).", "",
              "The steadiness tests are on the total stress, which the fluid part dominates above Mn 1e-2; the "
              "particle part, the magnetic effect, can still be moving while the total passes: its drift z is "
              "listed beside ('**' marks |z| > 3). Since session 25 a run's particle part counts as a measurement "
              f"only if it passes the particle-part rule: its drift |z| < {DRIFT_Z:g} and at least "
              f"{MIN_INDEPENDENT} independent samples in the window for it and for the total (docs/study.md, "
              "\"The particle part's rule\", fixed before any window it judges was run). It needs the version-2 "
              "estimate: older runs are 'untested'. A failing particle part is marked in the stress table and the "
              "slopes; the run's total keeps the policy above (the rule triggers no re-run).", "",
              "| model | Mn | seed | strain (warm-up) | drift z | MSER discard | steady | independent samples "
              "(version 2) | particle part: drift z, independent samples | particle-part rule | s per strain unit |",
              "|---|---:|---:|---:|---:|---:|---|---:|---:|---|---:|"]
    late = post_hoc(argv, here, rows)
    for r in sorted(rows, key=lambda r: (ORDER.index(r["model"]), float(r["mason"]), int(r["seed"]))):
        per = num(r, "wall_seconds") / num(r, "strain")
        ind = num(r, "stress_total_independent_samples")
        pz, pind = num(r, "stress_particles_drift_z"), num(r, "stress_particles_independent_samples")
        pzs = "–" if math.isnan(pz) else (f"**{pz:+.2f}**" if abs(pz) > DRIFT_Z else f"{pz:+.2f}")
        pcol = pzs + ("" if math.isnan(pind) else f", {pind:.0f}")
        pr = particle_rule(r)
        pr = pr if pr in ("ok", "untested") else f"**{pr}**"
        ph = late.get((r["model"], mkey(r["mason"]), int(r["seed"])))
        if pr == "untested" and ph:
            pr += f"; post hoc: {ph}"
        lines.append(f"| {r['model']} | {float(r['mason']):g} | {r['seed']} | {num(r, 'strain'):g} "
                     f"({num(r, 'warmup_strain'):g}) | {num(r, 'stress_total_drift_z'):+.2f} | "
                     f"{num(r, 'steady_mser_discard_fraction'):.3f} | {'yes' if steady(r) else '**no**'} | "
                     f"{'–' if math.isnan(ind) else f'{ind:.0f}'} | {pcol} | {pr} | {per:.3g} |")
    if late:
        bad = sorted(k for k, v in late.items() if v != "ok")
        lines += ["", f"Post hoc: {len(late)} runs that carry the plain estimate kept their averaging window "
                  "(window_series.csv in the archive) and were re-analysed with the version-2 estimate "
                  "(`mrf reanalyse`; reanalysed.json). Read by the particle-part rule, "
                  f"{len(bad)} of them fail: " + (", ".join(f"{m} Mn {mn:g} seed {sd}" for m, mn, sd in bad) or "none")
                  + ". These runs were seen before the rule was written: this is a reading, not a test of the rule, "
                  "and the tables above keep them 'untested'."]
    # The earlier runs of points re-run for steadiness (their summaries kept
    # in first_runs/ and second_runs/ before a re-run overwrote the archive
    # entry), each marked with its run number.
    firsts = []
    for number, key, sub in ((1, "--first-runs", "first_runs"), (2, "--second-runs", "second_runs"),
                             ("w", "--short-window-runs", "short_window_runs")):
        folder = arg(argv, key, os.path.join(here, "study", "paper", sub))
        for dirpath, _, files in sorted(os.walk(folder)) if os.path.isdir(folder) else []:
            if "summary.json" in files:
                firsts.append(dict(json.load(open(os.path.join(dirpath, "summary.json"))), run_number=number))
    current = {(r["model"], float(r["mason"]), int(r["seed"])): r for r in rows}
    if firsts:
        lines += ["", "Earlier runs of the points re-run for steadiness: run 1, the first run (re-run with strain and "
                  "warm-up doubled, session 21's rules); run 2, a re-run that failed again (run once more at 4x the "
                  "first run's strain, session 27's rule); run w, a coupled run at Mn 1e-3 that passed over strain 4-12, "
                  "run again over 16-48 by session 34's one-window rule; all at the end of "
                  "experiments/sweeps/paper_realistic.toml. "
                  "'in the table above' when that run is what the tables use (its re-run has not finished).", "",
                  "| model | Mn | seed | run | strain (warm-up) | drift z | MSER discard | steady | what the tables use now |",
                  "|---|---:|---:|---:|---:|---:|---:|---|---|"]
        for f in sorted(firsts, key=lambda f: (ORDER.index(f["model"]), f["mason"], f["seed"], str(f["run_number"]))):
            now = current.get((f["model"], float(f["mason"]), int(f["seed"])))
            if now is None:
                state = "pending; not in the tables"
            elif num(now, "strain") == f["strain"]:
                state = "pending; in the table above"
            else:
                state = (f"{num(now, 'strain'):g} ({num(now, 'warmup_strain'):g}): z {num(now, 'stress_total_drift_z'):+.2f}, "
                         f"MSER {num(now, 'steady_mser_discard_fraction'):.3f}, {'steady' if steady(now) else '**not steady**'}")
            ok = abs(f["stress_total_drift_z"]) < DRIFT_Z and f["steady_mser_discard_fraction"] < MSER_MAX
            lines.append(f"| {f['model']} | {f['mason']:g} | {f['seed']} | {f['run_number']} | "
                         f"{f['strain']:g} ({f['warmup_strain']:g}) | "
                         f"{f['stress_total_drift_z']:+.2f} | {f['steady_mser_discard_fraction']:.3f} | "
                         f"{'yes' if ok else '**no**'} | {state} |")
    return lines, firsts


def cost_section(st, firsts):
    """The whole sweep's wall time and the cost per strain unit per model and Mn."""
    rows, carrier, models, grid = st.rows, st.carrier, st.models, st.grid
    lines = ["", "Cost: wall seconds per strain unit of each run, one thread, on a shared 2-core machine "
              "(the sweep ran at nice 19 beside other work: an upper bound, not a benchmark; "
              "reports/performance/model_ratios.md has the side-by-side ratios).", ""]
    lines += sweep_cost(rows, firsts, [r for r in carrier if r["in_headline"] == "no"])
    # cost per strain unit per model and Mn: the fastest seed (the least
    # disturbed by other jobs), and its ratio to model 1's at the same Mn
    per = defaultdict(list)
    for r in rows:
        per[(r["model"], float(r["mason"]))].append(num(r, "wall_seconds") / num(r, "strain"))
    lines += ["Cost per strain unit: the fastest seed's wall seconds on one thread (the work; a run's wall time also "
              "holds the time its machine gave to other jobs, and some runs were paused while benchmarks ran, so seeds "
              "of the same steps and iterations can differ several times in wall time: an upper bound, and the "
              "ratios are rough), in brackets the ratio to model 1's at the same Mn:", "",
              "| model | " + " | ".join(f"Mn {m:g}" for m in grid) + " |", "|---|" + "---:|" * len(grid)]
    for k in models:
        cells = []
        for m in grid:
            v = min(per[(k, m)]) if per.get((k, m)) else float("nan")
            v1 = min(per[("dem_stokes", m)]) if per.get(("dem_stokes", m)) else float("nan")
            cells.append("–" if v != v else f"{v:.3g}" + ("" if k == "dem_stokes" or v1 != v1 else f" ({v / v1:.1f}x)"))
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def wall_volume(st):
    """Wall against volume-side stress: what model 1's imposed flow absorbs."""
    phi, models, grid, by = st.phi, st.models, st.grid, st.by
    lines = ["## Wall and volume-side stress per model", "",
              "Seed means over φμ0M²; volume side = the particle pair virial plus the carrier's part (model 1: "
              "eta gdot; models 2 and 3: the SPH virial and the exchange virial). m = 1 - wall/volume is the "
              "share of the particle stress that model 1's imposed flow absorbs instead of returning to the "
              "walls; a two-way model returns it (m near 0). Last column: each model's volume-side stress "
              "against the wall stress of demsph_dd at the same Mn.", "",
              "| model | Mn | seeds | wall | volume side | m | volume / wall(demsph_dd) - 1 |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for k in models:
        for m in grid:
            rs = by.get((k, m))
            if not rs:
                continue
            sc = phi * MU0 * num(rs[0], "magnetization") ** 2
            wall = sum(num(r, "stress_total") for r in rs) / len(rs) / sc
            vol = sum(num(r, "stress_virial_total") for r in rs) / len(rs) / sc
            ref = by.get(("demsph_dd", m))
            cmp3 = "–"
            if ref:
                w3 = sum(num(r, "stress_total") for r in ref) / len(ref) / sc
                cmp3 = f"{vol / w3 - 1:+.3f}"
            lines.append(f"| {k} | {m:g} | {len(rs)} | {wall:.4f} | {vol:.4f} | {1 - wall / vol:+.3f} | {cmp3} |")
    lines.append("")
    return lines


def preregistered(st):
    """The pre-registered model-1 criterion on this cell (its training data)."""
    lines = []
    pre = st.crit.get("preregistered_criterion", {}).get("points", [])
    if pre:
        lines += ["## The pre-registered model-1 criterion on this cell (training data)", "",
                  "delta = 1 - wall/(volume side + (g(phi) - 1) max(contact virial, 0)) of model 1's seed means "
                  "against the truth D = tau_1/tau_3 - 1 (docs/study.md, 'The pre-registered criterion'; "
                  "these points were seen when the rule was written: its test is reports/criterion/heldout.md).", "",
                  "| Mn | D | delta | m | verdict 10 % | verdict 20 % |", "|---:|---:|---:|---:|---|---|"]
        for q in pre:
            lines.append(f"| {q['mason']:g} | {q['deviation']:+.3f} ± {q['deviation_err']:.3f} | "
                         f"{q['shortfall']:.3f} ± {q['shortfall_err']:.3f} | {q['mismatch']:.3f} | "
                         f"{q['outcome_10']} | {q['outcome_20']} |")
        lines.append("")
    return lines


def quasistatic(st):
    """The quasi-static limit beside the lowest-Mn particle stresses."""
    crit, phi, models, qs, aqs_quote, seed_runs, by = st.crit, st.phi, st.models, st.qs, st.aqs_quote, \
        st.seed_runs, st.by
    lines = []
    if qs:
        lines += ["## The quasi-static limit (issue 17)", "",
                  "AQS wall stress of the paper cell (mrf quasistatic; reports/quasistatic/paper/), in φμ0M², beside "
                  "the particle part of each model's wall stress and model 1's volume side less eta gdot at the "
                  "lowest Mn run. In AQS there is no carrier and wall = virial at every minimum. The realisations "
                  "(seeds, increments) scatter by far more than each run's block error: the value to quote is "
                  "their mean with the standard error of their scatter over a common window "
                  "(reports/quasistatic/README.md §5).", "",
                  f"**Quoted: {aqs_quote[0]:.4f} ± {aqs_quote[1]:.4f} φμ0M²**, the mean of the {aqs_quote[2]} seeds "
                  f"({', '.join(seed_runs)}) over their common window, its error the standard error of their "
                  "scatter; the figure's star. The minimiser moves it beyond that scatter (rows lbfgs_*: L-BFGS "
                  "gives about 40 % less, reports/quasistatic/minimiser.md), so the quasi-static stress of this "
                  "model is a range by protocol. On the small cell, model 1's dynamic wall stress does not approach "
                  "the quasi-static one down to Mn = 1e-6 (reports/quasistatic/flow_vs_aqs.md). Convergence: the "
                  "cut-off (rows rc15*, rc24: 15 um is 35 % low, 24 um within 2 % of 20 um), the tolerance and the "
                  "increment pathwise from one minimum (reports/quasistatic/paper/pathwise.csv: tol 1e-6 -0.4 %, "
                  "d 2e-3 +8 % at 1.1 SE), the seeds (the quote's error).", "",
                  "| AQS run | stress / (phi mu0 M^2) | note |", "|---|---:|---|"]
        for r in qs:
            lines.append(f"| {r['run']} | {num(r, 'stress_over_phi_mu0_m2'):.5f} ± {num(r, 'err'):.5f} | "
                         f"{r.get('note', '')} |")
        lines += ["", "| model | lowest Mn | particle part of the wall stress | volume side - eta gdot |",
                  "|---|---:|---:|---:|"]
        for k in models:
            p = crit["models"][k]["points"]
            if not p:
                continue
            q = min(p, key=lambda q: q["mason"])
            sc = phi * MU0 * q["magnetization"] ** 2
            rs = by.get((k, q["mason"]), [])
            vol = (sum(num(r, "stress_virial_total") - num(r, "stress_fluid") for r in rs) / len(rs) / sc
                   if rs and k == "dem_stokes" else float("nan"))
            lines.append(f"| {k} | {q['mason']:g} | {(q['stress'] - q['stress_fluid']) / sc:.5f} ± "
                         f"{q['err'] / sc:.5f} | {'–' if math.isnan(vol) else f'{vol:.5f}'} |")
        lines.append("")
    return lines


def fits(st, open_mn, pstates):
    """mrf criterion's Bingham and power-law fits, and Delta at low Mn."""
    crit, phi, models = st.crit, st.phi, st.models
    lines = ["## Flow-curve fits (mrf criterion)", "",
              "eta/eta_inf = 1 + (Mn*/Mn)^Delta fitted to the seed-combined points (Bingham: Delta = 1). The "
              "Bingham fit's dynamic yield stress is tau_y / (phi mu0 M^2) = eta_r,inf Mn* / (4.5 phi) (REFERENCE.md "
              "§7, Bi = Mn*/Mn), = b/(4.5 phi) with b the fit's coefficient of 1/Mn and its error; "
              "a power law with Delta < 1 has no finite yield stress (tau ~ Mn^(1 - Delta) as Mn -> 0). chi2/dof far "
              "above 1 says that neither form fits within the points' errors (the errors are then inflated by it). "
              f"Beside them: the chain model's {CHAIN_YIELD:g}.", "",
              "| model | Bingham Mn* | Bingham tau_y / (phi mu0 M^2) | chi2/dof | power-law Mn* | Delta | chi2/dof | "
              "note |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    for k in models:
        b, pw = crit["models"][k]["bingham"], crit["models"][k]["power_law"]
        note = "" if pw["ok"] else pw.get("message", "")
        if b["ok"] and "slope" in b:  # b of eta_r = eta_inf + b/Mn, with its own error (covariance included)
            yield_ = f"{b['slope'] / (4.5 * phi):.4f} ± {b['slope_err'] / (4.5 * phi):.4f}"
        elif b["ok"] and b["mason_star"] > 0:  # an older criterion.json: the two errors in quadrature
            ty = b["eta_inf"] * b["mason_star"] / (4.5 * phi)
            yield_ = f"{ty:.4f} ± {ty * math.hypot(b['eta_inf_err'] / b['eta_inf'], b['mason_star_err'] / b['mason_star']):.4f}"
        else:
            yield_ = "– (" + (b.get("message") or "no fit") + ")"
        lines.append(f"| {k} | {b['mason_star']:.3g} ± {b['mason_star_err']:.2g} | {yield_} | "
                     f"{b['chi2_dof']:.2g} | {pw['mason_star']:.3g} ± {pw['mason_star_err']:.2g} | "
                     f"{pw['exponent']:.2f} ± {pw['exponent_err']:.2f} | {pw['chi2_dof']:.2g} | {note} |")
    lines.append("")
    # Delta at low Mn: eta/eta_inf - 1 ~ Mn^-Delta there, and the particle
    # part is tau - eta_inf gdot, so Delta = 1 - s of the particle part
    # between the two lowest Mn (the claims section's slope)
    low_d = []
    for k in models:
        p = sorted(crit["models"][k]["points"], key=lambda q: q["mason"])
        sl = lowest_slopes(p, lambda q: phi * MU0 * q["magnetization"] ** 2)[1] if len(p) >= 2 else None
        if sl is None:
            continue
        counts = [x + y for x, y in zip(*(pstates.get((k, mkey(q["mason"])), [0, 0, 0]) for q in p[:2]))]
        status = slope_status(k, p[0]["mason"], counts, open_mn)
        low_d.append(f"{k} {1 - sl[0]:.2f} ± {sl[1]:.2f}" + (f" ({status})" if status else ""))
    if low_d:
        lines += ["Delta at low Mn, from the particle part between the two lowest Mn (Delta = 1 - s, s its slope in "
                  "the claims section, with its status there; the fit above spans all five Mn): "
                  + "; ".join(low_d) + ".", ""]
    return lines


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    st = Study(argv)
    os.makedirs(st.out, exist_ok=True)
    crit, phi, rows, here, models, small, small_m = st.crit, st.phi, st.rows, st.here, st.models, st.small, st.small_m
    stress_figure(st)
    lines = opening_tables(st)
    steady_lines, firsts = steadiness(st)
    lines += steady_lines
    # the one-window rule's runs are the per-particle ones, in the headline or beside it (the carrier section)
    pp_low = [r for r in st.carrier if r["carrier"] == "per_particle"] or rows
    lines += one_window(pp_low, firsts, phi, arg(argv, "--points", os.path.join(here, "study", "paper", "points")))
    lines += carrier_section(st.carrier, arg(argv, "--common-points", os.path.join(here, "study", "paper",
                                                                                     "common_low", "points")))
    lines += cost_section(st, firsts)
    lines += wall_volume(st)
    lines += preregistered(st)
    lines += quasistatic(st)
    conv_points = arg(argv, "--convergence-points", os.path.join(here, "study", "paper", "convergence", "points"))
    open_mn, pstates = coupled_open_at(conv_points, rows, st.carrier), particle_state(rows)
    lines += fits(st, open_mn, pstates)
    lines += theory_and_experiment(crit, phi, st.expt, st.aqs_quote)
    low = low_mn(st.low_rows, crit, phi, st.aqs_quote, rows)
    long_lines = low_long(low_long_rows(argv, here), read_rows(st.transients) if os.path.exists(st.transients) else [],
                          phi)
    lines += low + long_lines
    small_crit_path = arg(argv, "--small-criterion", os.path.join(here, "study", "criterion_default.json"))
    small_crit = json.load(open(small_crit_path)) if os.path.exists(small_crit_path) else None
    claims = old_claims(crit, small_crit, phi, small_m, pstates, open_mn)
    lines += claims
    lines += two_paths(argv, here, crit, phi, models)
    unsteady = defaultdict(int)
    for r in rows:
        unsteady[(r["model"], mkey(r["mason"]))] += 0 if steady(r) else 1
    cost = next((x for x in lines if x.startswith("Whole-sweep wall time")), "")
    plateau = [f"Model 1 below Mn 1e-3 (its section below): {x}" for x in low + long_lines
               if x.startswith("s (3e-4 to 1e-3") or (x.startswith("Q1 at Mn") and " b = " in x)]
    head = answers(crit, small, phi, small_m, pstates, unsteady, claims, cost,
                   arg(argv, "--convergence", os.path.join(here, "study", "paper", "convergence.md")), plateau,
                   any(r["carrier"] == "common" and r["in_headline"] == "yes" for r in st.carrier))
    at = lines.index("![stress](stress_vs_mason.png)") + 2
    lines[at:at] = head
    with open(os.path.join(st.out, "paper.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"-> {os.path.join(st.out, 'paper.md')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
