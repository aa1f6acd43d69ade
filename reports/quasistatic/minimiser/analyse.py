#!/usr/bin/env python3
"""FIRE against L-BFGS in the quasi-static driver: the tables of
reports/quasistatic/minimiser.md from the run directories of run_scratch.sh
and run_pathwise.sh (default out/minimiser).

usage: analyse.py [RUN_ROOT] [OUT_DIR]

Writes OUT_DIR/scratch.csv (each run from the random packing: evaluations,
wall time, initial-minimum energy, mean wall stress after the warm-up) and
OUT_DIR/pathwise.csv (per minimum after the shared start, both minimisers,
with where the two paths part)."""
import csv
import json
import os
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "out/minimiser"
out = sys.argv[2] if len(sys.argv) > 2 else os.path.dirname(os.path.abspath(__file__))


def rows(run):
    with open(os.path.join(root, run, "quasistatic.csv")) as f:
        return list(csv.DictReader(f))


def summary(run):
    with open(os.path.join(root, run, "summary.json")) as f:
        return json.load(f)


scratch = [
    ("small", "2 GPa", "fire", 10, "1e-5", "small_y2_fire_tol1e-5"),
    ("small", "2 GPa", "fire", 10, "1e-6", "small_y2_fire_tol1e-6"),
    ("small", "2 GPa", "lbfgs", 10, "1e-5", "small_y2_lbfgs_tol1e-5"),
    ("small", "2 GPa", "lbfgs", 10, "1e-6", "small_y2_lbfgs_tol1e-6"),
    ("small", "2 GPa", "lbfgs", 3, "1e-6", "small_y2_lbfgs_m3_tol1e-6"),
    ("small", "2 GPa", "lbfgs", 30, "1e-6", "small_y2_lbfgs_m30_tol1e-6"),
    ("small", "200 GPa", "fire", 10, "1e-5", "small_y200_fire_tol1e-5"),
    ("small", "200 GPa", "lbfgs", 10, "1e-5", "small_y200_lbfgs_tol1e-5"),
    ("paper", "2 GPa", "fire", 10, "1e-5", "paper_y2_fire_tol1e-5"),
    ("paper", "2 GPa", "lbfgs", 10, "1e-5", "paper_y2_lbfgs_tol1e-5"),
]
with open(os.path.join(out, "scratch.csv"), "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["cell", "youngs_modulus", "minimiser", "memory", "tol_over_f0", "strain", "minima",
                "evaluations_initial", "evaluations_per_increment", "wall_seconds", "us_per_evaluation",
                "energy_initial_J", "stress_wall_mean_Pa", "stress_wall_err_Pa"])
    for cell, y, m, mem, tol, run in scratch:
        r, j = rows(run), summary(run)
        it = [int(x["iterations"]) + 1 for x in r]
        w.writerow([cell, y, m, mem if m == "lbfgs" else "", tol, r[-1]["strain"], len(r), it[0],
                    round(sum(it[1:]) / len(it[1:])), round(j["wall_seconds"], 2),
                    round(1e6 * j["wall_seconds"] / j["force_evaluations"], 1), r[0]["energy"],
                    round(j["stress_wall"], 1), round(j["stress_wall_err"], 1)])

pairs = [("small", "2 GPa", "1e-6", 0.2, "small_y2_fire_tol1e-6"),
         ("small", "200 GPa", "1e-5", 0.1, "small_y200_fire_tol1e-5"),
         ("paper", "2 GPa", "1e-5", 0.03, "paper_y2_fire_tol1e-5")]
with open(os.path.join(out, "pathwise.csv"), "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["cell", "youngs_modulus", "tol_over_f0", "branch_strain", "strain", "stress_wall_fire_Pa",
                "stress_wall_lbfgs_Pa", "energy_fire_J", "energy_lbfgs_J", "evaluations_fire", "evaluations_lbfgs"])
    for cell, y, tol, s0, base in pairs:
        a = [x for x in rows(base + "_fire_on") if float(x["strain"]) > s0 + 1e-9]
        b = [x for x in rows(base + "_lbfgs_branch") if float(x["strain"]) > s0 + 1e-9]
        parted = next((x["strain"] for x, q in zip(a, b)
                       if abs(float(x["stress_wall"]) - float(q["stress_wall"])) > 1.0), "none")
        ea = sum(int(x["iterations"]) + 1 for x in a)
        eb = sum(int(x["iterations"]) + 1 for x in b)
        ma = sum(float(x["stress_wall"]) for x in a) / len(a)
        mb = sum(float(x["stress_wall"]) for x in b) / len(b)
        print(f"{cell} {y} tol {tol}: from strain {s0}, {len(a)} increments; evaluations FIRE {ea}, L-BFGS {eb} "
              f"({ea / eb:.2f}x); mean wall stress FIRE {ma:.1f}, L-BFGS {mb:.1f} Pa; paths part (> 1 Pa) at {parted}")
        for x, q in zip(a, b):
            w.writerow([cell, y, tol, s0, x["strain"], x["stress_wall"], q["stress_wall"], x["energy"], q["energy"],
                        int(x["iterations"]) + 1, int(q["iterations"]) + 1])
print("wrote", os.path.join(out, "scratch.csv"), "and", os.path.join(out, "pathwise.csv"))
