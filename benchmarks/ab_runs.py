#!/usr/bin/env python3
"""Two mrf binaries side by side on the same runs: stress, steps, list builds
and CPU time (user + system of the run's process, which a busy machine
inflates less than wall time), alternating the binaries run by run.

    benchmarks/ab_runs.py OLD_BIN NEW_BIN --out DIR [--seeds 1 2 3]
        [--scene FILE] [--case NAME:MODEL:SETS ...] [--report FILE]

A case is a name, a model and ';'-separated --set overrides of the scene
(default experiments/scenes/small_dem_stokes.toml and the cases below). A run
whose summary.json exists is not run again, so an interrupted comparison
resumes. The report gives per run the stresses and their difference in
combined standard errors, and per case the seed means (error: the larger of
the seed scatter over sqrt(n) and the within-run errors combined,
sqrt(sum err^2) / n, as mrf criterion does) and the CPU-time ratio old / new.
"""
import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "experiments", "scenes", "small_dem_stokes.toml")
REALISTIC = "drive.vary='magnetization';drive.shear_rate=1e3"
CASES = [
    "m1_fixedM_0.01:dem_stokes:drive.mason=1e-2",
    "m1_1e3_0.1:dem_stokes:drive.mason=0.1;" + REALISTIC,
    "m1_1e3_0.001:dem_stokes:drive.mason=1e-3;" + REALISTIC,
    "m3_fixedM_0.01:demsph_dd:drive.mason=1e-2",
    "m3_1e3_0.1:demsph_dd:drive.mason=0.1;" + REALISTIC,
]


def run(binary, scene, out, model, sets, seed):
    summary = os.path.join(out, "summary.json")
    cpu_file = os.path.join(out, "cpu_seconds")
    if not (os.path.exists(summary) and os.path.exists(cpu_file)):
        cmd = [binary, "run", scene, "--quiet", "--out", out, "--checkpoint-every", "0",
               "--set", f'scene.model="{model}"', "--set", f"scene.seed={seed}", "--set", "numerics.threads=1"]
        for s in sets:
            cmd += ["--set", s]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(cmd, check=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        with open(cpu_file, "w") as f:
            f.write(f"{cpu}\n")
    j = json.load(open(summary))
    j["cpu_seconds"] = float(open(cpu_file).read())
    return j


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--out", required=True)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("--case", action="append", help="NAME:MODEL:SET;SET;...")
    ap.add_argument("--report", help="markdown file (default: stdout only)")
    a = ap.parse_args()
    cases = [c.split(":", 2) for c in (a.case or CASES)]
    lines = ["| run | old stress (Pa) | new stress (Pa) | diff (SE) | steps old/new | list builds old/new | CPU s old/new |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    summary = ["| case | old (Pa) | new (Pa) | diff (SE) | CPU old/new |", "|---|---:|---:|---:|---:|"]
    for name, model, sets in cases:
        sets = [s for s in sets.split(";") if s]
        res = {"old": [], "new": []}
        for seed in a.seeds:
            for which in ("old", "new") if seed % 2 else ("new", "old"):
                out = os.path.join(a.out, which, f"{name}_s{seed}")
                res[which].append(run(getattr(a, which), a.scene, out, model, sets, seed))
            o, n = res["old"][-1], res["new"][-1]
            z = (n["stress_total"] - o["stress_total"]) / math.hypot(o["stress_total_err"], n["stress_total_err"])
            lines.append(f"| {name} seed {seed} | {o['stress_total']:.1f} ± {o['stress_total_err']:.1f} | "
                         f"{n['stress_total']:.1f} ± {n['stress_total_err']:.1f} | {z:+.2f} | {o['steps']}/{n['steps']} | "
                         f"{o['neighbor_builds']}/{n['neighbor_builds']} | {o['cpu_seconds']:.2f}/{n['cpu_seconds']:.2f} |")

        def mean_err(rs):
            v = [r["stress_total"] for r in rs]
            within = math.sqrt(sum(r["stress_total_err"] ** 2 for r in rs)) / len(rs)
            scatter = statistics.stdev(v) / math.sqrt(len(v)) if len(v) > 1 else 0.0
            return statistics.mean(v), max(within, scatter)

        (mo, eo), (mn, en) = mean_err(res["old"]), mean_err(res["new"])
        cpu = sum(r["cpu_seconds"] for r in res["old"]) / sum(r["cpu_seconds"] for r in res["new"])
        summary.append(f"| {name} | {mo:.1f} ± {eo:.1f} | {mn:.1f} ± {en:.1f} | {(mn - mo) / math.hypot(eo, en):+.2f} | "
                       f"{cpu:.2f} |")
    text = "\n".join(summary) + "\n\n" + "\n".join(lines) + "\n"
    print(text)
    if a.report:
        with open(a.report, "w") as f:
            f.write(text)


if __name__ == "__main__":
    sys.exit(main())
