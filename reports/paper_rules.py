#!/usr/bin/python3
"""The paper report's rules (reports/paper_study.py writes the report with
them): the steadiness tests, the particle-part rule of session 25, the
small-cell claims and the plateau slopes, when the coupled values at Mn 1e-3
count (paper_convergence.toml, session 39), and the reading of model 1
below Mn 1e-3 (paper_low_mn.toml)."""
import json
import math
import os
import statistics
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paper_convergence import shift as convergence_shift  # noqa: E402
from study import MU0, ORDER, num, read_rows  # noqa: E402

DRIFT_Z, MSER_MAX = 3.0, 0.2  # steadiness tests of every point (DESIGN.md, issue 13)
# The particle-part rule, fixed in session 25 before any window it judges had
# been run (docs/study.md, "The particle part's rule"): a run's particle part
# is a measurement only if its drift |z| < 3 and both it and the total are
# worth at least MIN_INDEPENDENT independent samples (below 16 the drift test
# of a stationary AR(1) series flags > 10x its nominal rate). It needs the
# widened estimate (error_estimate_version 2); older runs are "untested".
MIN_INDEPENDENT = 16
def arg(argv, key, default):
    return argv[argv.index(key) + 1] if key in argv else default


def steady(r):
    z, d = num(r, "stress_total_drift_z"), num(r, "steady_mser_discard_fraction")
    return abs(z) < DRIFT_Z and d < MSER_MAX


def fe(e):
    """An error bar in phi mu0 M^2: four decimals, or two digits when smaller."""
    return f"{e:.4f}" if e >= 1e-4 else f"{e:.1e}"


def particle_rule(r):
    """'ok', 'untested' (a summary without the version-2 estimate) or the
    reasons the run's particle part fails the session-25 rule."""
    if not num(r, "error_estimate_version") >= 2:
        return "untested"
    pz = num(r, "stress_particles_drift_z")
    pind, tind = num(r, "stress_particles_independent_samples"), num(r, "stress_total_independent_samples")
    why = []
    if not abs(pz) < DRIFT_Z:
        why.append(f"particle drift z {pz:+.1f}")
    if not pind >= MIN_INDEPENDENT:
        why.append(f"particle part {pind:.0f} samples")
    if not tind >= MIN_INDEPENDENT:
        why.append(f"total {tind:.0f} samples")
    return "; ".join(why) if why else "ok"


def mkey(mn):
    """A Mason number as a dictionary key that sweep.csv and criterion.json agree on."""
    return float(f"{float(mn):.6g}")


def particle_state(rows):
    """Per (model, Mn): how many runs' particle parts fail the rule, how many
    are untested, how many runs."""
    st = defaultdict(lambda: [0, 0, 0])
    for r in rows:
        v = particle_rule(r)
        c = st[(r["model"], mkey(r["mason"]))]
        c[0] += v not in ("ok", "untested")
        c[1] += v == "untested"
        c[2] += 1
    return st


def particle_note(c):
    """The particle-part column's qualifier for a point: '' when every run
    passes the rule."""
    if not c or (c[0] == 0 and c[1] == 0):
        return ""
    return " (" + ", ".join(x for x in (f"{c[0]} fail" if c[0] else "", f"{c[1]} untested" if c[1] else "") if x) + ")"


def lowest_slopes(points, scale):
    """s = d ln(tau / scale) / d ln Mn between the two lowest Mn of seed-
    combined points (sorted by Mn), with its error, for the total and for
    the particle part (total - fluid part); None where a value is not
    positive."""
    a, b = points[0], points[1]
    out = []
    for part in (lambda q: q["stress"], lambda q: q["stress"] - q["stress_fluid"]):
        va, vb = part(a) / scale(a), part(b) / scale(b)
        if va <= 0 or vb <= 0:
            out.append(None)
            continue
        lr = math.log(b["mason"] / a["mason"])
        out.append((math.log(vb / va) / lr, math.hypot(a["err"] / scale(a) / va, b["err"] / scale(b) / vb) / lr))
    return out


def slope_status(k, lowest_mn, counts, open_mn):
    """Whether a slope from the two lowest Mn is a result: '' if so, else
    why not. counts: the two points' [fail, untested, runs] of the
    particle-part rule (a slope from failing runs is no measurement);
    open_mn: the Mn where the coupled values are not yet results."""
    if counts[0]:
        return "not a measurement"
    if k != "dem_stokes" and mkey(lowest_mn) in open_mn:
        return "not yet a result"
    return ""


def common_in_headline(carrier):
    """Whether the coupled points at Mn 1e-3 are the common-reference runs
    (paper_common_low.toml): carrier holds the rows of
    reports/study/paper/low_carrier.csv (scripts/paper_interim.py's
    carrier_swap), which says which carrier's runs the headline holds."""
    return any(r["carrier"] == "common" and r["in_headline"] == "yes" for r in carrier)


def coupled_open_at(conv, rows, carrier=()):
    """The Mn at which the coupled models' values are not yet results. Once
    the common-reference runs stand in the headline (common_in_headline:
    every point of paper_common_low.toml, the re-runs the rule below called
    for, finished), none. Before: at
    Mn 1e-3, until every coupled run there is averaged over strain 16-48
    (paper_realistic.toml's one-window rule) and both coupled carrier rows
    (convergence variant eos_common_low) are in the convergence archive
    `conv` and neither differs from its base by more than 2 combined
    standard errors (paper_convergence.toml, fixed in session 39: otherwise
    the points are to be run again with the common reference); a missing
    archive leaves it open. `conv` = "none" (a sweep with
    no carrier study, as the report's check builds): nothing is open."""
    if conv == "none" or common_in_headline(carrier):
        return set()
    low = {k: [r for r in rows if r["model"] == k and mkey(r["mason"]) == 1e-3] for k in ("demsph_stokes", "demsph_dd")}
    windows = all((num(r, "warmup_strain"), num(r, "strain")) == (16.0, 48.0) for v in low.values() for r in v)
    carrier = {}
    for k in low:
        path = os.path.join(conv, k, "eos_common_low", "mn_0.001_seed_1", "summary.json")
        if os.path.exists(path) and low[k]:
            carrier[k] = convergence_shift(json.load(open(path)), low[k])[4]
    # paper_convergence.toml (session 39): results only if neither row moves
    # by more than 2 combined standard errors; otherwise they await a re-run
    closed = windows and len(carrier) == 2 and all(abs(z) <= 2 for z in carrier.values())
    return set() if closed else {mkey(1e-3)}


def old_claims(crit, small_crit, phi, small_m, pstate=None, open_mn=()):
    """The small-cell study's claims (reports/study/study.md, the claims that
    issue 13 names) against the same quantities on the paper cell. A claim
    holds at a point when the paper-cell value lies within the claimed range
    to two standard errors; at a Mn of open_mn (coupled values not yet
    results) the verdict is shown as read and not counted."""
    if not small_crit:
        return []
    dev = {k: {q["mason"]: q for q in v["points"]} for k, v in crit.get("deviation_from_demsph_dd", {}).items()}
    sdev = {k: {q["mason"]: q for q in v["points"]} for k, v in small_crit.get("deviation_from_demsph_dd", {}).items()}
    lines = ["## The small-cell study's claims, re-measured on the paper cell", "",
             "Each claim of reports/study/study.md (375 spheres, fixed M, 2 seeds) against the same quantity "
             "on the paper cell (realistic path, 3 seeds). D_k = tau_k / tau_3 - 1 (wall stress against model 3 "
             "at the same Mn, mrf criterion's deviation_from_demsph_dd); 'holds' when the paper-cell value is "
             "inside the claimed range to 2 standard errors.", "",
             "| claim | Mn | small cell | paper cell | holds on the paper cell |", "|---|---:|---:|---:|---|"]

    def row(claim, m, sq, pq, lo, hi, key="deviation", err=True):
        sv = f"{sq[key]:+.3f}" + (f" ± {sq['err']:.3f}" if err else "") if sq else "–"
        if not pq:
            return f"| {claim} | {m:g} | {sv} | – | – |"
        v, e = pq[key], (pq["err"] if err else 0.0)
        ok = lo - 2 * e <= v <= hi + 2 * e
        verdict = "yes" if ok else "**no**"
        if mkey(m) in open_mn:
            verdict = f"{'yes' if ok else 'no'} as read, not counted: the coupled values at this Mn are not yet results"
        return f"| {claim} | {m:g} | {sv} | {v:+.3f}" + (f" ± {e:.3f}" if err else "") + f" | {verdict} |"

    grid = sorted({m for v in dev.values() for m in v})
    for m in grid:
        lines.append(row("model 1 is 27-68 % below model 3 at every Mn (D_1 in [-0.68, -0.27])", m,
                         sdev.get("dem_stokes", {}).get(m), dev.get("dem_stokes", {}).get(m), -0.68, -0.27))
    for m in [m for m in grid if m <= 1.0]:
        lines.append(row("models 2 and 3 agree within 10 % up to Mn about 1 (abs(D_2) <= 0.10)", m,
                         sdev.get("demsph_stokes", {}).get(m), dev.get("demsph_stokes", {}).get(m), -0.10, 0.10))
    for m in [m for m in grid if 1e-2 <= m <= 1.0]:
        lines.append(row("model 1's volume-side stress is within 11 % of model 3 for 1e-2 <= Mn <= 1 "
                         "(no error: seed means)", m, sdev.get("dem_stokes", {}).get(m),
                         dev.get("dem_stokes", {}).get(m), -0.11, 0.11, key="volume_deviation", err=False))
    # "No yield plateau down to Mn = 1e-3": the local slope of the
    # normalised stress between the two lowest Mn (0 = a plateau, a yield
    # stress; 1 = Newtonian), for the total and the particle part, beside
    # the power-law exponent of the flow-curve fit.
    lines += ["", "The yield plateau: s = d ln(tau / phi mu0 M^2) / d ln Mn between the two lowest Mn "
              "(s = 0 is a plateau, a Mn-independent yield stress; s = 1 a Newtonian flow), of the total and of "
              "the particle part, and the power-law fit's Delta (1 = Bingham). The small-cell claim was that "
              "there is no plateau down to Mn = 1e-3. The last column: is the particle part flat (|s| within 2 "
              "standard errors of 0)? The total's slope is then the carrier's viscous stress (eta gdot, in these "
              "units proportional to Mn); the flat particle stress is not the quasi-static value (the AQS section "
              "below).", "",
              "In brackets after the paper cell's particle slope: how many of the two points' runs fail the "
              "particle-part rule (steadiness section) or predate it (untested); a slope from failing runs is "
              "not a measurement.", "",
              "| model | cell | Mn pair | s (total) | s (particle part) | Delta (fit) | particle part flat |",
              "|---|---|---|---:|---:|---:|---|"]

    def slopes(c, k, scale, states=None):
        p = sorted(c["models"].get(k, {}).get("points", []), key=lambda q: q["mason"])
        if len(p) < 2:
            return None
        a, b = p[0], p[1]
        note, counts = "", [0, 0, 0]
        if states is not None:
            sa, sb = states.get((k, mkey(a["mason"]))), states.get((k, mkey(b["mason"])))
            counts = [x + y for x, y in zip(sa or [0, 0, 0], sb or [0, 0, 0])]
            note = particle_note(counts)
        out = [f"{a['mason']:g}-{b['mason']:g}"]
        flat = "–"
        for slope in lowest_slopes(p, scale):
            if slope is None:
                out.append("–")
                flat = "–"
                continue
            sl, se = slope
            out.append(f"{sl:+.2f} ± {se:.2f}")
            flat = "yes" if abs(sl) <= 2 * se else "no"  # the last part: the particle part
        out[-1] += note
        status = slope_status(k, a["mason"], counts, open_mn) if states is not None else ""
        if status and flat != "–":
            flat = f"{status} ({'flat' if flat == 'yes' else 'not flat'} as read)"
        pw = c["models"][k].get("power_law", {})
        out.append(f"{pw.get('exponent', float('nan')):.2f} ± {pw.get('exponent_err', float('nan')):.2f}")
        return out + [flat]

    for k in [m for m in ORDER if m in crit["models"]]:
        for name, c, scale, states in (("paper", crit, lambda q: phi * MU0 * q["magnetization"] ** 2, pstate),
                                       ("small", small_crit,
                                        lambda q: small_crit["volume_fraction"] * MU0 * small_m ** 2, None)):
            s = slopes(c, k, scale, states)
            if s:
                lines.append(f"| {k} | {name} | " + " | ".join(s) + " |")
    lines.append("")
    return lines


def drift_signs(runs):
    """How many of the runs' total stress drifts inside their windows
    (negative drift z), how many runs, and the two-sided sign-test p of
    that count against no drift."""
    n = len(runs)
    k = sum(1 for r in runs if num(r, "stress_total_drift_z") < 0)
    tail = sum(math.comb(n, i) for i in range(min(k, n - k) + 1)) / 2 ** n
    return k, n, min(1.0, 2 * tail)


def seed_combined(rows, phi, particle_part=True):
    """The seed mean of runs of one point in phi mu0 M^2 (the particle part,
    or the total), its error max(within-run combined for the mean, seed
    scatter / sqrt(n)), and those two: (mean, err, within, scatter)."""
    n = len(rows)
    sc = [phi * MU0 * num(r, "magnetization") ** 2 for r in rows]
    vals = [(num(r, "stress_total") - (num(r, "stress_fluid") if particle_part else 0.0)) / c
            for r, c in zip(rows, sc)]
    within = math.sqrt(sum((num(r, "stress_total_err") / c) ** 2 for r, c in zip(rows, sc))) / n
    scatter = statistics.stdev(vals) / math.sqrt(n) if n > 1 else 0.0
    return sum(vals) / n, max(within, scatter), within, scatter


def low_mn_rows(argv, here):
    """Model 1's finished runs of experiments/sweeps/paper_low_mn.toml."""
    path = arg(argv, "--low-mn", os.path.join(here, "study", "paper", "low_mn_sweep.csv"))
    if not os.path.exists(path):
        return None
    return [r for r in read_rows(path) if r["status"] == "ok" and r["model"] == "dem_stokes"]


def low_long_rows(argv, here):
    """Model 1's finished runs of experiments/sweeps/paper_model1_low_long.toml
    (its own sweep.csv, collected by scripts/paper_interim.py), None without it."""
    path = arg(argv, "--low-long", os.path.join(here, "study", "paper", "model1_low_long", "sweep.csv"))
    if not os.path.exists(path):
        return None
    return [r for r in read_rows(path) if r["status"] == "ok" and r["model"] == "dem_stokes"]


LOW_LONG = "paper_model1_low_long"  # its runs' sweep name in transients.csv


def slope_between(lo_rows, hi_rows, phi, lo=3e-4, hi=1e-3):
    """The particle part's slope s = ln(v_hi / v_lo) / ln(hi / lo) between two
    points of seed-combined runs (seed_combined), and its error."""
    v_lo, e_lo, _, _ = seed_combined(lo_rows, phi)
    v_hi, e_hi, _, _ = seed_combined(hi_rows, phi)
    lr = math.log(hi / lo)
    return math.log(v_hi / v_lo) / lr, math.hypot(e_lo / v_lo, e_hi / v_hi) / lr


def plateau_verdict(slope, err):
    return ("is flat (a plateau)" if abs(slope) <= 2 * err else
            "falls toward the quasi-static value" if slope > 0 else "rises as Mn falls")


def low_long(rows, transients, phi):
    """experiments/sweeps/paper_model1_low_long.toml, read as fixed there
    before its runs (session 39). Q1 per Mn: d = a run's particle part over
    strain 16-48 less that over 4-12 (plain means of its 4-unit bins in
    transients.csv), b = the seeds' mean d, SE = SD(d) / sqrt(n); |b| > 2 SE
    says the 12-unit window (4-12) was not settled. Q2: the particle part's
    slope between 3e-4 and 1e-3 from these runs' 16-48 windows alone, read as
    low_mn reads it. At least 2 seeds per Mn, else not read."""
    if rows is None:
        return []
    lines = ["### Model 1 over long windows at Mn 3e-4 and 1e-3", "",
             "experiments/sweeps/paper_model1_low_long.toml (fixed before its runs, session 39): model 1, seeds 1-3, "
             "48 strain units with 16 of warm-up; its reading is in that file. Particle part = total less fluid part.",
             "", "| Mn | seed | particle part 4-12 (Pa) | 16-48 (Pa) | d (Pa) | drift z | MSER-5 | steady |",
             "|---:|---:|---:|---:|---:|---:|---:|---|"]
    by_mn = {m: sorted((r for r in rows if mkey(r["mason"]) == m), key=lambda r: int(r["seed"])) for m in (3e-4, 1e-3)}
    q1 = []
    for m, group in by_mn.items():
        ds = []
        for r in group:
            bins = [t for t in transients if t["sweep"] == LOW_LONG and mkey(t["mason"]) == m and t["seed"] == r["seed"]]
            part = lambda a, b: [num(t, "stress_particles_Pa") for t in bins  # noqa: E731
                                 if num(t, "strain_lo") >= a - 1e-9 and num(t, "strain_hi") <= b + 1e-9]
            early, late = part(4, 12), part(16, 48)
            d = statistics.mean(late) - statistics.mean(early) if early and late else float("nan")
            if math.isfinite(d):
                ds.append(d)
            lines.append(f"| {m:g} | {r['seed']} | " + (f"{statistics.mean(early):.2f}" if early else "no bins") + " | "
                         + (f"{statistics.mean(late):.2f}" if late else "no bins") + " | "
                         + (f"{d:+.2f}" if math.isfinite(d) else "-") + f" | {num(r, 'stress_total_drift_z'):+.2f} | {num(r, 'steady_mser_discard_fraction'):.3f} | "
                         + ("yes" if steady(r) else "**no**") + " |")
        if len(ds) < 2:
            q1.append(f"Q1 at Mn {m:g}: {len(ds)} run(s) with both windows: not read (at least 2).")
            continue
        b, se = statistics.mean(ds), statistics.stdev(ds) / math.sqrt(len(ds))
        q1.append(f"Q1 at Mn {m:g}: b = {b:+.2f} ± {se:.2f} Pa ({len(ds)} seeds): the 12-unit window "
                  + ("**was not settled**" if abs(b) > 2 * se else "was settled") + " by the reading fixed in advance.")
    lines += [""] + q1 + [""]
    if min(len(g) for g in by_mn.values()) < 2:
        return lines + [f"Q2: {len(by_mn[3e-4])} and {len(by_mn[1e-3])} runs at Mn 3e-4 and 1e-3: not read (at least 2 "
                        "each).", ""]
    slope, err = slope_between(by_mn[3e-4], by_mn[1e-3], phi)
    return lines + [f"s (3e-4 to 1e-3, 16-48 windows) = {slope:+.3f} ± {err:.3f}: by the reading fixed in advance, the "
                    f"particle stress **{plateau_verdict(slope, err)}**.", ""]


def low_mn(rows, crit, phi, aqs_quote, main_rows=()):
    """Model 1 at Mn 3e-4 (experiments/sweeps/paper_low_mn.toml; rows from
    low_mn_rows, None without its table), read as that file fixed before its
    runs: the particle part's slope s from Mn 1e-3 (the realistic sweep's
    point) within 2 standard errors of 0 is a plateau, above it a fall toward
    the quasi-static value, below a rise."""
    if rows is None:
        return []
    base = next((q for q in crit["models"].get("dem_stokes", {}).get("points", []) if mkey(q["mason"]) == 1e-3), None)
    lines = ["## Model 1 below Mn 1e-3: is there a plateau?", "",
             "experiments/sweeps/paper_low_mn.toml: model 1, Mn = 3e-4 on the realistic path, three seeds; its "
             "reading was fixed in that file before the runs: the slope s of the particle part "
             "tau_p/(phi mu0 M^2) from Mn 1e-3 within 2 standard errors of 0 is a plateau (a dynamic yield "
             "stress), above that the stress falls toward the quasi-static value, below it rises. Errors: "
             "max(within-run, seed scatter / sqrt(n)); each run also under the steadiness tests and the "
             "particle-part rule.", ""]
    if not rows or base is None:
        return lines + [f"No run has finished yet ({len(rows)} of 3).", ""]
    n = len(rows)
    mean, err, within, scatter = seed_combined(rows, phi)
    bs = phi * MU0 * base["magnetization"] ** 2
    bv, be = (base["stress"] - base["stress_fluid"]) / bs, base["err"] / bs
    lr = math.log(1e-3 / 3e-4)
    slope, slope_err = math.log(bv / mean) / lr, math.hypot(err / mean, be / bv) / lr
    verdict = plateau_verdict(slope, slope_err)
    bad = [r["seed"] for r in rows if not steady(r)]
    pfail = [r["seed"] for r in rows if particle_rule(r) not in ("ok", "untested")]
    lines += ["| Mn | seeds | particle part | note |", "|---:|---:|---:|---|",
              f"| 3e-4 | {n} | {mean:.4f} ± {fe(err)} | "
              + (f"seed scatter / within-run {scatter / within:.2f}" if n > 1 and within > 0 else
                 "one seed: within-run error only, which the seed scatter can exceed several times")
              + (f"; not steady: seeds {', '.join(bad)}" if bad else "")
              + (f"; particle-part rule not passed: seeds {', '.join(pfail)}" if pfail else "")
              + ("; runs without the version-2 estimate (the rule untested)"
                 if any(particle_rule(r) == "untested" for r in rows) else "") + " |",
              f"| 1e-3 | {base['seeds']} | {bv:.4f} ± {fe(be)} | the realistic sweep |"]
    if math.isfinite(aqs_quote[0]):
        lines.append(f"| 0 (AQS) | {aqs_quote[2]} | {aqs_quote[0]:.4f} ± {fe(aqs_quote[1])} | quasi-static limit |")
    lines += ["", f"s (3e-4 to 1e-3) = {slope:+.3f} ± {slope_err:.3f}: by the reading fixed in advance, the particle "
              f"stress **{verdict}**" + (f" ({n} of 3 seeds so far: provisional)" if n < 3 else "")
              + (" (with runs that fail a steadiness test or the particle-part rule: read with that caveat)"
                 if bad or pfail else "") + ".", ""]
    at_base = [r for r in main_rows if r["model"] == "dem_stokes" and mkey(r["mason"]) == 1e-3]
    if at_base:
        k, nb, p = drift_signs(at_base)
        kl, nl, pl = drift_signs(rows)
        lines += [f"Within the windows: {k} of the {nb} runs at Mn 1e-3 and {kl} of the {nl} at 3e-4 drift downward "
                  f"(negative drift z; two-sided sign test p = {p:.3f} and {pl:.3f})"
                  + (", every one of them within the drift test. " if all(steady(r) for r in at_base + rows) else ". ")
                  + "Where nearly every window of a point still falls, that point has not settled (its settled "
                  "value lies lower), and a slope to it holds its transient as well as the Mn.", ""]
    return lines
