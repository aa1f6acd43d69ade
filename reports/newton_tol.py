#!/usr/bin/python3
"""What the implicit schemes' Newton tolerance moves
(experiments/sweeps/newton_tol.toml): per model and Mn, the wall stress of
each tolerance (seed mean, error max(within-run, seed scatter / sqrt(n))),
its shift from the default 1e-6 R in combined standard errors, and the work
(steps, Newton and CG iterations, wall time summed over the seeds).

usage: newton_tol.py SWEEP_CSV OUT_MD
"""
import csv
import math
import statistics
import sys
from collections import defaultdict

BASE = "newton_1e-6"


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    rows = [r for r in csv.DictReader(open(argv[1])) if r["status"] == "ok"]
    g = defaultdict(list)
    for r in rows:
        g[(r["model"], float(r["mason"]), r["variant"])].append(r)

    def f(r, k):
        return float(r[k])

    def mean_err(rs):
        s = [f(r, "stress_total") for r in rs]
        m = statistics.mean(s)
        scatter = statistics.stdev(s) / math.sqrt(len(s)) if len(s) > 1 else 0.0
        return m, max(max(f(r, "stress_total_err") for r in rs), scatter)

    lines = ["# The implicit schemes' Newton tolerance", "",
             "experiments/sweeps/newton_tol.toml (written before it ran): the small cell on the paper study's path "
             "(1000 1/s, M from Mn, Y = 200 GPa, `auto`), models 1 and 3, strain 6 (2 of warm-up), 3 seeds; "
             "numerics.newton_tol = the largest overlap residual / R at which a step's contact Newton solve stops. "
             "Written by reports/newton_tol.py. Stress: seed mean with max(within-run, seed scatter / sqrt(n)); "
             "shift against the default 1e-6 in combined standard errors; work summed over the seeds.", "",
             "| model | Mn | newton_tol | wall stress (Pa) | shift (sigma) | contact virial (Pa) | steps | Newton / step "
             "| CG / Newton | wall s |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    shifts = []
    for (k, mn, v) in sorted(g, key=lambda t: (t[0], t[1], -float(t[2].split("_")[1]))):
        rs = g[(k, mn, v)]
        m, e = mean_err(rs)
        base = g.get((k, mn, BASE))
        shift = "–"
        if base and v != BASE:
            bm, be = mean_err(base)
            shifts.append((abs(m - bm) / math.hypot(e, be), k, mn, v))
            shift = f"{(m - bm) / math.hypot(e, be):+.1f}"
        steps = sum(f(r, "steps") for r in rs)
        newton = sum(f(r, "implicit_newton_iterations") for r in rs)
        cg = sum(f(r, "implicit_linear_iterations") for r in rs)
        contact = statistics.mean(f(r, "stress_virial_contact") for r in rs)
        lines.append(f"| {k} | {mn:g} | {v.split('_')[1]} | {m:.1f} ± {e:.1f} | {shift} | {contact:.1f} | "
                     f"{steps:.0f} | {newton / steps:.1f} | {cg / newton:.1f} | "
                     f"{sum(f(r, 'wall_seconds') for r in rs):.1f} |")
    if shifts:
        z, k, mn, v = max(shifts)
        lines += ["", f"Largest shift from the default: {z:.1f} combined standard errors ({k}, Mn {mn:g}, "
                  f"{v.split('_')[1]}), over {len(shifts)} comparisons. Whether a looser tolerance pays: the wall "
                  "seconds and steps above (a Newton solve stopped early leaves an error that the step's error "
                  "estimate can see as its own)."]
    with open(argv[2], "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print(f"-> {argv[2]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
