#!/usr/bin/env python3
"""ctest MpiSweep (when mrf is built with MPI): a 4-point sweep (models 1 and 3,
Mn 0.3 and 1) under `mpirun -n 3 --oversubscribe` (rank 0 schedules, two
workers run) against the same sweep run serially: every point's
summary.json equal field by field, bit for bit in the text of each number,
timing fields aside; one complete sweep.csv with the same rows.

On the way, a dead worker: the first point's run is killed with SIGKILL
from outside (as the OOM killer would) while it runs; the sweep must report
that point as not finished, finish the others, and exit with status 4; the
sweep run again resumes the point from its checkpoint, and the result is
then compared with the serial sweep like every other point.

Usage: mpi_sweep_check.py MPIEXEC MRF_BINARY SCENE WORKDIR
"""
import json, os, pathlib, shutil, signal, subprocess, sys, time

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
mpi = [mpiexec, "-n", "3", "--oversubscribe", mrf, "sweep", str(sweep), "--out", str(work / "mpi"),
       "--checkpoint-every", "0.1"]
first = subprocess.Popen(mpi, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
victim, t0 = None, time.monotonic()
while victim is None and first.poll() is None and time.monotonic() - t0 < 60:
    for line in subprocess.run(["ps", "-eo", "pid=,etimes=,args="], capture_output=True, text=True).stdout.splitlines():
        pid, _, args = line.split(None, 2)
        if "--point" in args and str(work / "mpi") in args:
            # its checkpoint exists: the kill lands mid-run, not before the first step
            point = args.split("--point")[1].split()[0]
            if list((work / "mpi").glob("*/*/checkpoint.bin")):
                victim = (int(pid), point)
                os.kill(int(pid), signal.SIGKILL)
                break
    time.sleep(0.02)
log = first.communicate()[0]
print(log)
assert victim is not None, "no point's run was seen to kill"
assert first.returncode == 4, f"a sweep with a dead point must exit 4, not {first.returncode}"
assert "did not finish" in log and "killed by signal 9" in log, "the dead point is not reported"
finished = len(list((work / "mpi").glob("*/*/summary.json")))
assert finished == 3, f"the other points must finish: {finished} of 4 did"
print(f"killed point {victim[1]} (pid {victim[0]}): reported, the other 3 finished, exit 4")
subprocess.run(mpi, check=True, env=env)
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
