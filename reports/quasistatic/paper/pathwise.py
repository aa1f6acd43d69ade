#!/usr/bin/python3
"""Pathwise tolerance and increment tests on the paper cell (issue 17):
runs branched (mrf quasistatic --branch-from) from one L-BFGS minimum at
strain 0.45 (seed 1, Y 2 GPa, r_c 20 um, tol 1e-5 F0, d 1e-2) and taken on
to 0.7 with one setting changed, against the run that went on unchanged.

usage: /usr/bin/python3 reports/quasistatic/paper/pathwise.py [RUN_ROOT]   (default out/aqs_path)
RUN_ROOT holds ref/ (d 1e-2, tol 1e-5: the reference path) and any of
tol1e-6/, d5e-3/, d2e-3/. Writes pathwise.csv beside this script: per run,
the mean wall stress after the branch point and its standard error (minima
are correlated: a lower bound), the first strain at which it parts from
the reference by more than 5 equilibrium bounds N (gap/2) tol / V (70 Pa;
at the reference's strains),
and the force evaluations after the branch."""
import csv
import json
import math
import os
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "out/aqs_path"
here = os.path.dirname(os.path.abspath(__file__))
branch_strain = 0.45


def series(run):
    rows = list(csv.DictReader(open(os.path.join(root, run, "quasistatic.csv"))))
    return [(float(r["strain"]), float(r["stress_wall"]), int(r["iterations"]) + 1) for r in rows]


ref_summary = json.load(open(os.path.join(root, "ref", "summary.json")))
scale = ref_summary["stress_scale"]
apart = 5 * ref_summary["equilibrium_bound"]
ref = series("ref")
ref_at = {round(s, 6): w for s, w, _ in ref}
out = []
for run, label in [("ref", "d 1e-2, tol 1e-5 (reference)"), ("tol1e-6", "tol 1e-6"), ("d5e-3", "d 5e-3"),
                   ("d2e-3", "d 2e-3")]:
    if not os.path.exists(os.path.join(root, run, "quasistatic.csv")):
        continue
    done = os.path.exists(os.path.join(root, run, "summary.json"))
    after = [(s, w, e) for s, w, e in series(run) if s > branch_strain + 1e-9]
    if not after:
        continue
    w = [x[1] for x in after]
    m = sum(w) / len(w)
    sem = math.sqrt(sum((v - m) ** 2 for v in w) / (len(w) - 1) / len(w)) if len(w) > 1 else float("nan")
    parted = next((f"{s:.3f}" for s, v, _ in after if round(s, 6) in ref_at and abs(v - ref_at[round(s, 6)]) > apart),
                  "none")
    out.append([label, f"{after[0][0]:.3f}-{after[-1][0]:.3f}", len(after), f"{m / scale:.5f}", f"{sem / scale:.5f}",
                round(m, 1), round(sem, 1), parted, sum(x[2] for x in after), int(done)])
with open(os.path.join(here, "pathwise.csv"), "w", newline="") as f:
    wr = csv.writer(f)
    wr.writerow(["run", "window", "minima", "mean_over_phi_mu0_m2", "sem_over_phi_mu0_m2", "mean_Pa", "sem_Pa",
                 "parts_from_reference_at", "evaluations", "finished"])
    wr.writerows(out)
for r in out:
    print(r)
