#!/usr/bin/env python3
"""The sweep schedule measured (issue 15): a synthetic sweep whose point costs
vary 30x, on 2 workers, scheduled three ways, side by side in one run:

  round-robin   `mrf sweep --rank 0 --ranks 2` and `--rank 1 --ranks 2`
                started together (point index mod 2, the deal before MPI);
  master-worker `mpirun -n 3 mrf sweep` (rank 0 hands out the points, the
                most expensive estimate first; ranks 1 and 2 run them);
  claims        `mrf sweep` started twice on one output (each process takes
                the next point in grid order that nobody claims).

The 8 points are model 3 (demsph_dd) on the small scene; points 0 and 2
run 30x the strain of the other six, so that round-robin gives both long
points to the same rank. The best possible wall time on 2 workers is
max(largest point, total / 2), from the points' own wall_seconds. Each
schedule runs in a fresh output folder.

Usage: benchmarks/schedule.py [--mrf build/mrf] [--mpiexec mpirun] [--report reports/performance/schedule.md]
"""
import argparse, datetime, json, os, pathlib, shutil, subprocess, time

root = pathlib.Path(__file__).resolve().parent.parent
ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--mrf", default=str(root / "build" / "mrf"))
ap.add_argument("--mpiexec", default="mpirun")
ap.add_argument("--work", default="/tmp/mrf_schedule")
ap.add_argument("--short-strain", type=float, default=1.2)
ap.add_argument("--report", default=str(root / "reports" / "performance" / "schedule.md"))
a = ap.parse_args()

work = pathlib.Path(a.work)
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
short, long_ = a.short_strain, 30 * a.short_strain
sweep = work / "synthetic.toml"
sweep.write_text(f"""[sweep]
scene = "{root}/experiments/scenes/small_demsph_dd.toml"
models = ["demsph_dd"]
mason = [0.10, 0.11, 0.12, 0.13, 0.14, 0.15, 0.16, 0.17]
seeds = [1]
set = ["numerics.threads=1", "drive.strain={short}", "drive.warmup_strain={short / 3}"]
[[rule]]
mason_max = 0.105
set = ["drive.strain={long_}", "drive.warmup_strain={long_ / 3}"]
[[rule]]
mason_min = 0.115
mason_max = 0.125
set = ["drive.strain={long_}", "drive.warmup_strain={long_ / 3}"]
""")
env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def timed(cmds):
    t0 = time.monotonic()
    procs = [subprocess.Popen(c, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for c in cmds]
    codes = [p.wait() for p in procs]
    assert all(c == 0 for c in codes), (cmds, codes)
    return time.monotonic() - t0


def points(out):
    return {str(p.parent.relative_to(out)): json.loads(p.read_text())["wall_seconds"]
            for p in out.glob("*/*/summary.json")}


rr = work / "round_robin"
mw = work / "master_worker"
cl = work / "claims"
base = [a.mrf, "sweep", str(sweep), "--quiet", "--checkpoint-every", "0"]
t_rr = timed([base + ["--out", str(rr), "--rank", str(r), "--ranks", "2"] for r in (0, 1)])
t_mw = timed([[a.mpiexec, "-n", "3", "--oversubscribe"] + base + ["--out", str(mw)]])
t_cl = timed([base + ["--out", str(cl)] for _ in (0, 1)])
rows = []
for name, out, wall in (("round-robin (index mod 2)", rr, t_rr), ("master-worker (mpirun -n 3)", mw, t_mw),
                        ("claims (two `mrf sweep` on one output)", cl, t_cl)):
    p = points(out)
    assert len(p) == 8, (name, p)
    total, largest = sum(p.values()), max(p.values())
    best = max(largest, total / 2)
    rows.append((name, wall, total, largest, min(p.values()), best))
rev = subprocess.run([a.mrf, "--version"], capture_output=True, text=True).stdout.strip()
lines = [
    "# The sweep schedule on 2 workers (benchmarks/schedule.py)",
    "",
    f"{datetime.date.today()}, {rev}, {os.cpu_count()} logical CPUs, one thread per point. A synthetic sweep: 8 points "
    f"of model 3 on the small scene, six of {short:g} strain units and two (points 0 and 2) of {long_:g}. "
    "Best possible = max(largest point, total / 2), from the points' own wall_seconds in the same run.",
    "",
    "| schedule | wall (s) | sum of points (s) | largest / smallest point (s) | best possible (s) | wall / best |",
    "|---|---:|---:|---:|---:|---:|",
]
for name, wall, total, largest, smallest, best in rows:
    lines.append(f"| {name} | {wall:.1f} | {total:.1f} | {largest:.1f} / {smallest:.2f} ({largest / smallest:.0f}x) "
                 f"| {best:.1f} | **{wall / best:.2f}** |")
lines += ["", "Target (issue 15): master-worker within 1.2x of the best possible."]
text = "\n".join(lines) + "\n"
print(text)
pathlib.Path(a.report).parent.mkdir(parents=True, exist_ok=True)
pathlib.Path(a.report).write_text(text)
