#!/usr/bin/python3
"""Tables and figure of reports/quasistatic/flow_vs_aqs.md from the run
directories of flow/run.sh.

usage: /usr/bin/python3 reports/quasistatic/flow/analyse.py [RUN_ROOT]   (default out/flowprep)

Writes beside this script:
  dynamic.csv  one row per dynamic run: Mn, seed, the wall stress of the
               particles (stress_particles) with its block error, drift z and
               MSER discard fraction, the virial, wall - virial (the drag's
               share), wall seconds;
  aqs.csv      one row per quasi-static run: its start (packing or the last
               frame of the run at Mn), minimiser, the first minimum's wall
               stress, the mean over the later minima, its standard error
               (minima are correlated: a lower bound), the first minimum's
               energy and iterations;
  flow_vs_aqs.png  stress / (phi mu0 M^2) against Mn: dynamic seeds and
               their mean, the AQS from the flow at each Mn, the AQS from
               the packing as a band.
"""
import csv
import glob
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

root = sys.argv[1] if len(sys.argv) > 1 else "out/flowprep"
here = os.path.dirname(os.path.abspath(__file__))

dyn = []
scale = None
for d in sorted(glob.glob(os.path.join(root, "run_mn*_s*"))):
    m = re.search(r"run_mn([0-9.e+-]+)_s(\d+)$", d)
    if not m or not os.path.exists(os.path.join(d, "summary.json")):
        continue
    j = json.load(open(os.path.join(d, "summary.json")))
    # phi mu0 M^2 with phi as built: N V_p / V
    n, r = j["n_particles"], j["radius"]
    phi = n * 4.0 / 3.0 * math.pi * r**3 / (j["gap"] * j["box_ly"] * j["box_lz"])
    scale = phi * 4e-7 * math.pi * j["magnetization"] ** 2
    dyn.append(dict(mn=float(m.group(1)), seed=int(m.group(2)), stress=j["stress_particles"],
                    err=j["stress_particles_err"], drift_z=j["stress_particles_drift_z"],
                    mser=j["steady_mser_discard_fraction"], virial=j["stress_virial"],
                    wall_minus_virial=j["stress_wall_minus_virial"], strain=j["strain"],
                    seconds=j["wall_seconds"], scale=scale))
dyn.sort(key=lambda x: (-x["mn"], x["seed"]))
with open(os.path.join(here, "dynamic.csv"), "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["mason", "seed", "strain", "stress_particles_Pa", "err_Pa", "over_phi_mu0_m2", "drift_z",
                "mser_discard", "steady", "virial_Pa", "wall_minus_virial_Pa", "wall_seconds"])
    for x in dyn:
        steady = abs(x["drift_z"]) < 3 and x["mser"] < 0.2
        w.writerow([x["mn"], x["seed"], x["strain"], round(x["stress"], 1), round(x["err"], 1),
                    f"{x['stress'] / x['scale']:.5f}", round(x["drift_z"], 2), round(x["mser"], 2), int(steady),
                    round(x["virial"], 1), round(x["wall_minus_virial"], 1), round(x["seconds"], 1)])

aqs = []
for q in sorted(glob.glob(os.path.join(root, "aqs_*")) + glob.glob(os.path.join(root, "relax_*"))):
    if not os.path.exists(os.path.join(q, "summary.json")):
        continue
    name = os.path.basename(q)
    m = re.match(r"(aqs|relax)_(mn([0-9.e+-]+)|packing)_s(\d+)_(\w+)$", name)
    if not m:
        continue
    rows = list(csv.DictReader(open(os.path.join(q, "quasistatic.csv"))))
    wall = [float(r["stress_wall"]) for r in rows]
    later = wall[1:]
    mean = sum(later) / len(later) if later else float("nan")
    sd = math.sqrt(sum((v - mean) ** 2 for v in later) / (len(later) - 1)) if len(later) > 1 else float("nan")
    aqs.append(dict(kind=m.group(1), start=("packing" if m.group(2) == "packing" else "flow"),
                    mn=float(m.group(3)) if m.group(3) else None, seed=int(m.group(4)), minimiser=m.group(5),
                    first=wall[0], mean=mean, sem=sd / math.sqrt(len(later)) if later else float("nan"),
                    minima=len(wall), tol=json.load(open(os.path.join(q, "summary.json")))["force_tol_over_f0"],
                    energy=float(rows[0]["energy"]), iterations=int(rows[0]["iterations"])))
with open(os.path.join(here, "aqs.csv"), "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["kind", "start", "mason_of_flow", "seed", "minimiser", "tol_over_f0", "minima", "first_minimum_Pa",
                "mean_later_Pa", "sem_later_Pa", "mean_over_phi_mu0_m2", "first_energy_J", "first_iterations"])
    for x in aqs:
        w.writerow([x["kind"], x["start"], x["mn"] if x["mn"] else "", x["seed"], x["minimiser"], x["tol"], x["minima"],
                    round(x["first"], 1), round(x["mean"], 1) if x["minima"] > 1 else "",
                    round(x["sem"], 1) if x["minima"] > 2 else "",
                    f"{x['mean'] / scale:.5f}" if x["minima"] > 1 and scale else "", x["energy"], x["iterations"]])

if scale:
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    mns = sorted({x["mn"] for x in dyn}, reverse=True)
    for x in dyn:
        steady = abs(x["drift_z"]) < 3 and x["mser"] < 0.2
        ax.errorbar(x["mn"], x["stress"] / scale, yerr=x["err"] / scale, fmt="o" if steady else "x", color="C0",
                    alpha=0.6, ms=5)
    means = [sum(x["stress"] for x in dyn if x["mn"] == m) / sum(1 for x in dyn if x["mn"] == m) / scale for m in mns]
    ax.plot(mns, means, "-", color="C0", label="dynamic model 1, wall stress of the particles (x: not steady)")
    flow = [x for x in aqs if x["kind"] == "aqs" and x["start"] == "flow" and x["minima"] > 1]
    for i, x in enumerate(flow):
        ax.plot(x["mn"] * (1.12 if x["minimiser"] == "lbfgs" else 0.89), x["mean"] / scale,
                "s" if x["minimiser"] == "fire" else "^", color="C1" if x["minimiser"] == "fire" else "C2", ms=5,
                label=None if i > 1 else None)
    ax.plot([], [], "s", color="C1", label="AQS from the flow at that Mn (FIRE)")
    ax.plot([], [], "^", color="C2", label="AQS from the flow at that Mn (L-BFGS)")
    pk = [x["mean"] / scale for x in aqs if x["kind"] == "aqs" and x["start"] == "packing" and x["minima"] > 1]
    if pk:
        ax.axhspan(min(pk), max(pk), color="0.8", alpha=0.6, label=f"AQS from the packing ({len(pk)} runs)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("Mn")
    ax.set_ylabel(r"wall stress / ($\phi\,\mu_0 M^2$)")
    ax.set_title("Small cell, Y = 2 GPa: flow against quasi-static shear")
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(os.path.join(here, "flow_vs_aqs.png"), dpi=120)
print(f"{len(dyn)} dynamic runs, {len(aqs)} quasi-static runs -> {here}/dynamic.csv, aqs.csv, flow_vs_aqs.png")
