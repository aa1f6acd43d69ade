#!/usr/bin/python3
"""The study report (issue 6): stress and relative viscosity against Mason
number for the three models with theory and experiment, the deviation of
models 1 and 2 from model 3 with the criterion, and the cost per strain unit.

usage: study.py SWEEP_DIR OUT_DIR [--title TEXT] [--heldout DIR]...

SWEEP_DIR holds sweep.csv (mrf sweep) and criterion.json (mrf criterion).
Writes OUT_DIR/study.md, PNG+SVG figures and CSV tables. Every figure states
the Mason-number convention and the scene parameters.
"""
import csv
import json
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MU0 = 4e-7 * math.pi
MN_CONVENTION = "Mn = 9 eta gdot / (2 mu0 M^2)"
LABEL = {"dem_stokes": "1: DEM-Stokes (one-way)", "demsph_stokes": "2: DEM-SPH Stokes", "demsph_dd": "3: DEM-SPH Di Felice"}
COLOR = {"dem_stokes": "tab:blue", "demsph_stokes": "tab:orange", "demsph_dd": "tab:green"}
ORDER = ["dem_stokes", "demsph_stokes", "demsph_dd"]
CHAIN_YIELD = 0.13738  # tau_y / (phi mu0 M^2), point-dipole chains, REFERENCE TEST 1.5
GINDER_SAT = 0.086     # tau_sat / (phi mu0 Ms^2), Ginder, Davis & Elie 1996
KRIEGER = 2.75         # Krieger-Dougherty eta/eta_carrier at phi 0.3, phi_m 0.64 (REFERENCE section 8)


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def num(row, key):
    try:
        return float(row[key])
    except (KeyError, ValueError):
        return float("nan")


def strain_bin(rows, key, lo, hi):
    """Plain mean of column `key` over the time-series rows with lo < strain
    <= hi (a row's strain is the end of the interval it averages); nan for an
    empty bin."""
    v = [float(r[key]) for r in rows if lo < float(r["strain"]) <= hi]
    return sum(v) / len(v) if v else float("nan")


def save(fig, out, name):
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{name}.{ext}"), dpi=110, bbox_inches="tight")
    plt.close(fig)


def params_line(rows):
    r = next(r for r in rows if r["status"] == "ok")
    eta = num(r, "stress_fluid") / num(r, "shear_rate") if r["model"] == "dem_stokes" else float("nan")
    return (f"{MN_CONVENTION}; phi = {num(r, 'volume_fraction'):.2f}, M = {num(r, 'magnetization'):.3g} A/m, "
            f"Y = {num(r, 'youngs_modulus'):.3g} Pa, eta = {eta:.3g} Pa s, {int(num(r, 'n_particles'))} particles")


def experiment_points(path):
    """Yield stresses near phi 0.3 as tau_y/(phi mu0 M^2), from experiments/data."""
    pts = []
    if not os.path.exists(path):
        return pts
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    for r in rows:
        v = num(r, "tau_over_phi_mu0_M2")
        if math.isfinite(v) and abs(num(r, "volume_fraction") - 0.3) < 0.05 and r["source_id"] != "DANG2000":
            pts.append((r["source_id"], num(r, "field_H_A_per_m"), v))
    return pts


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    sweep_dir, out = argv[1], argv[2]
    heldout = [argv[i + 1] for i, a in enumerate(argv) if a == "--heldout"]
    title = argv[argv.index("--title") + 1] if "--title" in argv else os.path.basename(os.path.normpath(sweep_dir))
    os.makedirs(out, exist_ok=True)
    rows = [r for r in read_rows(os.path.join(sweep_dir, "sweep.csv"))]
    ok = [r for r in rows if r["status"] == "ok"]
    crit = json.load(open(os.path.join(sweep_dir, "criterion.json")))
    phi, m = crit["volume_fraction"], crit["magnetization"]
    scale = phi * MU0 * m * m
    plabel = params_line(rows)
    models = [k for k in ORDER if k in crit["models"]]
    here = os.path.dirname(os.path.abspath(__file__))
    expt = experiment_points(os.path.join(here, "..", "experiments", "data", "experiment_mrf.csv"))

    # ---- stress against Mn --------------------------------------------------
    fig, ax = plt.subplots(figsize=(7.5, 5))
    mns_all = []
    for k in models:
        p = crit["models"][k]["points"]
        x = [q["mason"] for q in p]
        mns_all += x
        ax.errorbar(x, [q["stress"] / scale for q in p], yerr=[q["err"] / scale for q in p], fmt="o-", ms=4,
                    capsize=3, color=COLOR[k], label=LABEL[k])
    lo, hi = min(mns_all) / 2, max(mns_all) * 2
    grid = [lo * (hi / lo) ** (i / 100) for i in range(101)]
    ax.plot(grid, [CHAIN_YIELD + KRIEGER * (2 / 9) * g / phi for g in grid], "k--", lw=1,
            label="chain model yield 0.137 + Krieger-Dougherty viscosity")
    ax.axhline(GINDER_SAT, color="gray", ls=":", lw=1, label="Ginder saturation 0.086 (Ms = M)")
    sources = sorted({e[0] for e in expt})
    for src in sources:
        vals = [v for s_, _, v in expt if s_ == src]
        mk = "s^vD<>"[sources.index(src) % 6]
        ax.plot([lo * 1.2] * len(vals), vals, marker=mk, color="tab:red", ms=5, ls="none",
                label=f"experiment {src}: yield stress at {len(vals)} fields")
    ax.set(xscale="log", yscale="log", xlabel=f"Mason number ({MN_CONVENTION})",
           ylabel="shear stress / (phi mu0 M^2)", title=f"{title}: shear stress")
    ax.legend(fontsize=7)
    ax.text(0.01, -0.16, plabel + "; experiment: yield stress (no shear rate), drawn at the left edge",
            transform=ax.transAxes, fontsize=6)
    save(fig, out, "stress_vs_mason")

    # ---- relative viscosity with fits ----------------------------------------
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for k in models:
        p = crit["models"][k]["points"]
        ax.errorbar([q["mason"] for q in p], [q["eta_r"] for q in p], yerr=[q["eta_r_err"] for q in p], fmt="o",
                    ms=4, capsize=3, color=COLOR[k], label=LABEL[k])
        f = crit["models"][k]["power_law"]
        if f["ok"]:
            ax.plot(grid, [f["eta_inf"] * (1 + (f["mason_star"] / g) ** f["exponent"]) for g in grid], "-",
                    color=COLOR[k], lw=1,
                    label=f"fit: Mn* = {f['mason_star']:.2g} +- {f['mason_star_err']:.1g}, "
                          f"Delta = {f['exponent']:.2f} +- {f['exponent_err']:.2f}")
    ax.set(xscale="log", yscale="log", xlabel=f"Mason number ({MN_CONVENTION})",
           ylabel="eta_r = tau / (eta gdot)", title=f"{title}: relative viscosity, eta_r = eta_inf (1 + (Mn*/Mn)^Delta)")
    ax.legend(fontsize=7)
    ax.text(0.01, -0.16, plabel, transform=ax.transAxes, fontsize=6)
    save(fig, out, "relative_viscosity")

    # ---- deviation from model 3 ----------------------------------------------
    dev = crit.get("deviation_from_demsph_dd", {})
    if dev:
        fig, axs = plt.subplots(1, 2, figsize=(13, 4.8))
        for k, d in dev.items():
            p = d["points"]
            axs[0].errorbar([q["mason"] for q in p], [100 * q["deviation"] for q in p],
                            yerr=[100 * q["err"] for q in p], fmt="o-", ms=4, capsize=3, color=COLOR[k],
                            label=LABEL[k] + " (wall stress)")
            if k == "dem_stokes":
                axs[0].plot([q["mason"] for q in p], [100 * q["volume_deviation"] for q in p], "s--", ms=4,
                            color=COLOR[k], label="1: volume stress (pair virial + eta gdot)")
        for i, (h, mk) in enumerate([(sweep_dir, "o")] + [(x, "^") for x in heldout]):
            path = os.path.join(h, "criterion.json")
            if not os.path.exists(path):
                continue
            d1 = json.load(open(path)).get("deviation_from_demsph_dd", {}).get("dem_stokes")
            if d1:
                color = f"C{i}"
                for q in d1["points"]:
                    inertial = q.get("reynolds", 0) >= 0.05
                    axs[1].plot([100 * q["mismatch"]], [-100 * q["deviation"]], mk, ms=6, color=color,
                                mfc="none" if inertial else color)
                axs[1].plot([], [], mk, color=color, label=os.path.basename(os.path.normpath(h)))
        axs[1].plot([], [], "o", color="gray", mfc="none", label="open: Re_p >= 0.05 (criterion says not adequate)")
        axs[1].plot([0, 100], [0, 100], "k:", lw=1, label="-deviation = mismatch")
        for lvl in (10, 20):
            axs[1].axvline(lvl, color="gray", ls="--", lw=0.8)
            axs[1].axhline(lvl, color="gray", ls="--", lw=0.8)
        axs[0].axhspan(-10, 10, color="gray", alpha=0.1)
        axs[0].axhspan(-20, 20, color="gray", alpha=0.06)
        axs[0].axhline(0, color="k", lw=0.5)
        axs[0].set(xscale="log", xlabel=f"Mason number ({MN_CONVENTION})", ylabel="tau_model / tau_3 - 1 (%)",
                   title="deviation from model 3 (DEM-SPH Di Felice)")
        axs[1].set(xlabel="model-1 self-consistency mismatch m = 1 - tau_wall / tau_volume (%)",
                   ylabel="model 1 shortfall 1 - tau_1 / tau_3 (%)",
                   title="criterion: adequate at a when |m| < a and Re_p < 0.05")
        for ax in axs:
            ax.legend(fontsize=7)
        axs[0].text(0.01, -0.2, plabel, transform=axs[0].transAxes, fontsize=6)
        save(fig, out, "deviation")

    # ---- cost per strain unit ------------------------------------------------
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    cost = defaultdict(list)
    for r in ok:
        cost[r["model"]].append((num(r, "mason"), num(r, "wall_seconds") / num(r, "strain")))
    for k in models:
        pts = sorted(cost[k])
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=COLOR[k], label=LABEL[k])
    ax.set(xscale="log", yscale="log", xlabel=f"Mason number ({MN_CONVENTION})", ylabel="wall seconds per strain unit",
           title=f"{title}: cost (one core per run)")
    ax.legend(fontsize=7)
    ax.text(0.01, -0.18, plabel, transform=ax.transAxes, fontsize=6)
    save(fig, out, "cost")

    # ---- tables and the report -----------------------------------------------
    with open(os.path.join(out, "flow_curves.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["model", "mason", "stress_Pa", "err_Pa", "seed_scatter_Pa", "within_err_Pa", "seeds",
                    "stress_fluid_Pa", "eta_r", "eta_r_err"])
        for k in models:
            for q in crit["models"][k]["points"]:
                w.writerow([k, q["mason"], q["stress"], q["err"], q["seed_scatter"], q["within_err"], q["seeds"],
                            q["stress_fluid"], q["eta_r"], q["eta_r_err"]])
    md = [f"# Study: shear stress against Mason number — {title}", "",
          f"{plabel}.", "",
          "Generated by `reports/study.py` from `sweep.csv` and `criterion.json` of `mrf sweep` / `mrf criterion`.", "",
          "![stress](stress_vs_mason.png)", "", "![relative viscosity](relative_viscosity.png)", ""]
    if dev:
        md += ["![deviation](deviation.png)", ""]
    md += ["![cost](cost.png)", "", "## Flow-curve fits (GSL, errors from the covariance, inflated by chi2/dof > 1)", "",
           "| model | Bingham eta_inf | Bingham Mn* | chi2/dof | power-law eta_inf | Mn* | Delta | chi2/dof |",
           "|---|---|---|---|---|---|---|---|"]
    for k in models:
        b, p = crit["models"][k]["bingham"], crit["models"][k]["power_law"]
        fb = (lambda v, e: f"{v:.3g} ± {e:.2g}")
        md.append(f"| {k} | {fb(b['eta_inf'], b['eta_inf_err'])} | {fb(b['mason_star'], b['mason_star_err'])} | "
                  f"{b['chi2_dof']:.2g} | {fb(p['eta_inf'], p['eta_inf_err'])} | {fb(p['mason_star'], p['mason_star_err'])} | "
                  f"{fb(p['exponent'], p['exponent_err'])} | {p['chi2_dof']:.2g} |"
                  + ("" if p["ok"] else f" ({p['message']})"))
    md += ["", "## Seed-averaged points", "",
           "| model | Mn | tau (Pa) | error (Pa) | seed scatter (Pa) | within-run (Pa) | seeds | hydrodynamic share |",
           "|---|---|---|---|---|---|---|---|"]
    for k in models:
        for q in crit["models"][k]["points"]:
            md.append(f"| {k} | {q['mason']:.3g} | {q['stress']:.4g} | {q['err']:.2g} | {q['seed_scatter']:.2g} | "
                      f"{q['within_err']:.2g} | {q['seeds']} | {q['stress_fluid'] / q['stress']:.3f} |")
    md += ["## Cost per strain unit (wall seconds, mean over seeds, one core per run, two runs at a time)", "",
           "| Mn | " + " | ".join(models) + " | " + " | ".join(f"{k}/dem_stokes" for k in models if k != "dem_stokes") + " |",
           "|---|" + "---|" * (2 * len(models) - 1)]
    for mn in sorted({p_[0] for k in models for p_ in cost[k]}):
        means = {k: sum(c for m_, c in cost[k] if m_ == mn) / max(1, sum(1 for m_, _ in cost[k] if m_ == mn))
                 for k in models}
        ratios = [f"{means[k] / means['dem_stokes']:.2f}" for k in models if k != "dem_stokes" and "dem_stokes" in means]
        md.append(f"| {mn:.3g} | " + " | ".join(f"{means[k]:.3g}" for k in models) + " | " + " | ".join(ratios) + " |")
    md.append("")
    drift = [r for r in ok if abs(num(r, "stress_total_drift_z")) > 3]
    md += ["", f"Drift check: {len(drift)} of {len(ok)} runs have |z| > 3 between the halves of the averaging window"
           + (": " + ", ".join(r["dir"] for r in drift) if drift else "."), ""]
    mser = [r for r in ok if num(r, "steady_mser_discard_fraction") > 0.2]
    md += [f"Steady-state check (MSER-5 on the averaging window): {len(mser)} of {len(ok)} runs would still discard "
           "more than 20 % of the window as transient" + (": " + ", ".join(
               f"{r['dir']} ({100 * num(r, 'steady_mser_discard_fraction'):.0f} %)" for r in mser) if mser else "."), ""]
    d1 = dev.get("dem_stokes")
    if d1:
        pts = d1["points"]
        worst = max(abs(q["deviation"]) for q in pts)
        best = min(abs(q["deviation"]) for q in pts)
        mid = [q for q in pts if 1e-2 <= q["mason"] <= 1]
        vol = max(abs(q["volume_deviation"]) for q in mid) if mid else float("nan")
        md += ["## Findings", "",
               f"- Model 1's wall stress lies {100 * best:.0f}-{100 * worst:.0f} % away from model 3 over the whole sweep: "
               "its imposed fluid absorbs the stress of clusters that do not reach a wall, which the two-way models "
               "carry to the walls through the fluid.",
               "- **Criterion (checkable on one DEM-Stokes run):** the self-consistency mismatch of the run, "
               "m = 1 - tau_wall / tau_volume with tau_volume = pair virial + eta gdot, estimates model 1's shortfall "
               "1 - tau_1/tau_3 (to about 0.1 for Mn <= 0.1); model 1 is adequate at accuracy a when |m| < a "
               "and the particle Reynolds number Re_p = rho_f gdot R^2 / eta < 0.05 (`mrf criterion RUN_DIR`). "
               "Provisional: the Reynolds clause was chosen after two held-out sweeps. At phi = 0.10, model 1 was "
               "off by 18-47 % at Mn >= 1 with |m| <= 0.1. A Stokes-number clause was tried first and refuted by "
               "10x lighter particles (still off by 19-39 % at St 0.03-0.09). The extra stress of the two-way fluid "
               "follows its Reynolds number, which model 1's imposed Stokes profile cannot show. "
               "On the independent final test (heldout_final, run once after the criterion was fixed) the verdicts "
               "were right 5 of 8 times: all three misses are conservative, at Re_p 0.05-0.17 where model 1 was "
               "within 9-19 %, and |m| alone would have scored 7 of 8. Verdicts right on this sweep: "
               f"{100 * d1.get('consistency_hit_rate', float('nan')):.0f} %; held-out sweeps below.",
               f"- Model 1's volume-side stress is within {100 * vol:.0f} % of model 3 for 1e-2 <= Mn <= 1 "
               "(not at Mn 1e-3 or 10): the cheap model is usable there if its volume stress is reported.", ""]
    if dev:
        md += ["## Deviation from model 3 and the criterion", "",
               "| model | Mn | tau/tau_3 - 1 | ± | hydrodynamic share s | mismatch m = 1 - tau_wall/tau_volume | "
               "volume stress/tau_3 - 1 |", "|---|---|---|---|---|---|---|"]
        for k, d in dev.items():
            for q in d["points"]:
                md.append(f"| {k} | {q['mason']:.3g} | {q['deviation']:+.3f} | {q['err']:.3f} | {q['share']:.3f} | "
                          f"{q['mismatch']:+.3f} | {q['volume_deviation']:+.3f} |")
        md.append("")
        for k, d in dev.items():
            for lvl, key in ((10, "crossing_10"), (20, "crossing_20")):
                c = d[key]
                if c.get("below_range"):
                    md.append(f"- {k}: off by more than {lvl} % already at the lowest Mn of the sweep ({c['mason']:.3g})")
                elif c["found"]:
                    md.append(f"- {k}: off by {lvl} % from Mn = {c['mason']:.3g} (share s = {c['share']:.3f})")
                else:
                    md.append(f"- {k}: within {lvl} % over the whole sweep")
            if "consistency_hit_rate" in d:
                md.append(f"- {k}: self-consistency verdicts right: {100 * d['consistency_hit_rate']:.0f} %")
    for h in heldout:
        path = os.path.join(h, "criterion.json")
        if not os.path.exists(path):
            md += ["", f"### Held-out conditions: `{h}`: no criterion.json"]
            continue
        hc = json.load(open(path))
        d1 = hc.get("deviation_from_demsph_dd", {}).get("dem_stokes", {})
        md += ["", f"### Held-out conditions: `{os.path.basename(os.path.normpath(h))}`", "",
               f"phi = {hc['volume_fraction']:.2f}; self-consistency verdicts right: "
               f"{100 * d1.get('consistency_hit_rate', float('nan')):.0f} %", "",
               "| Mn | tau_1/tau_3 - 1 | mismatch m | verdict 10 % right | verdict 20 % right | volume stress/tau_3 - 1 |",
               "|---|---|---|---|---|---|"]
        for q in d1.get("points", []):
            md.append(f"| {q['mason']:.3g} | {q['deviation']:+.3f} | {q['mismatch']:+.3f} | {q.get('consistency_hit_10', '')} | "
                      f"{q.get('consistency_hit_20', '')} | {q['volume_deviation']:+.3f} |")
    wp = [("DEM integrators on the small scene: explicit soft/stiff Y and implicit (verification of issue 7)",
           os.path.join(here, "work_precision", "implicit_small_scene.png")),
          ("SPH start-up Couette flow: explicit and implicit viscosity", os.path.join(here, "sph", "work_precision.png"))]
    md += ["", "## Work–precision figures from the verification suites", ""]
    for caption, path in wp:
        if os.path.exists(path):
            md += [f"{caption}:", "", f"![{caption}]({os.path.relpath(path, out)})", ""]
    md += ["Sensitivity of the stress to seed, Young's modulus, density, dipole cutoff and box size: "
           f"[sensitivity.md]({os.path.relpath(os.path.join(here, 'sensitivity.md'), out)})."]
    with open(os.path.join(out, "study.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print(f"wrote {out}/study.md and figures")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
