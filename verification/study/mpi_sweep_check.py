#!/usr/bin/env python3
"""ctest MpiSweep (when mrf is built with MPI): a 4-point sweep (models 1 and 3,
Mn 0.3 and 1) under `mpirun -n 3 --oversubscribe` (rank 0 schedules, two
workers run) against the same sweep run serially: every point's
summary.json equal field by field, bit for bit in the text of each number,
timing fields aside; one complete sweep.csv with the same rows.

Usage: mpi_sweep_check.py MPIEXEC MRF_BINARY SCENE WORKDIR
"""
import json, os, pathlib, shutil, subprocess, sys

mpiexec, mrf, scene, work = sys.argv[1], sys.argv[2], sys.argv[3], pathlib.Path(sys.argv[4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
sweep = work / "tiny.toml"
sweep.write_text(f"""[sweep]
scene = "{scene}"
models = ["dem_stokes", "demsph_dd"]
mason = [0.3, 1.0]
seeds = [3]
set = ["drive.strain=0.6", "drive.warmup_strain=0.2", "numerics.threads=1"]
""")
env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
subprocess.run([mpiexec, "-n", "3", "--oversubscribe", mrf, "sweep", str(sweep), "--out", str(work / "mpi")],
               check=True, env=env)
subprocess.run([mrf, "sweep", str(sweep), "--out", str(work / "serial"), "--quiet"], check=True, env=env)
timing = lambda k: "second" in k or k == "threads"
bad = 0
points = sorted(p.relative_to(work / "serial") for p in (work / "serial").glob("*/*/summary.json"))
assert len(points) == 4, points
for rel in points:
    a = json.loads((work / "serial" / rel).read_text(), parse_float=str)
    b = json.loads((work / "mpi" / rel).read_text(), parse_float=str)
    for k in a:
        if not timing(k) and a[k] != b.get(k):
            print(f"{rel} {k}: serial {a[k]} mpi {b.get(k)}")
            bad += 1
rows = lambda d: sorted(l.split(",")[:3] for l in (work / d / "sweep.csv").read_text().splitlines()[1:])
if rows("mpi") != rows("serial") or len(rows("mpi")) != 4:
    print("sweep.csv rows differ:", rows("mpi"), rows("serial"))
    bad += 1
print(f"MPI sweep against serial: {len(points)} points, {bad} differences")
sys.exit(1 if bad else 0)
