#!/usr/bin/env python3
"""ctest SweepClaims: two `mrf sweep` processes started at once on one sweep
output share its points through the points' claims (study/point_claim.hpp).

A sweep of 4 points of model 1 (about a second each). Both processes must
end with status 0; every point must be finished, each by exactly one of
them: the "N run" of the two summary lines add up to 4, and the points each
says it ran are disjoint, 4 in all. Without claims both would run every
point (8 runs, and two runs writing one folder). While they run, `--list`
is polled and must call a point "running" at least once. Each summary.json
must equal, in its stress, that of the same point run alone.

Usage: sweep_claim_check.py MRF_BINARY SCENE WORKDIR
"""
import json
import pathlib
import re
import shutil
import subprocess
import sys
import time

mrf, scene, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
sweep = work / "four.toml"
sweep.write_text(f"""[sweep]
scene = "{scene}"
models = ["dem_stokes"]
mason = [0.3, 1.0]
seeds = [1, 2]
set = ["drive.strain=1.5", "drive.warmup_strain=0.5", "numerics.threads=1"]
""")
out = work / "shared"
procs = [subprocess.Popen([mrf, "sweep", str(sweep), "--out", str(out)], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True) for _ in range(2)]
saw_running = False
while any(p.poll() is None for p in procs):
    listing = subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--list"], capture_output=True,
                             text=True).stdout
    saw_running |= any(len(f) > 5 and f[5] == "running" for f in (ln.split() for ln in listing.splitlines()[1:]))
    time.sleep(0.05)
ran_total, ran_points = 0, []
for p in procs:
    stdout, stderr = p.communicate()
    assert p.returncode == 0, f"a sweep ended with status {p.returncode}:\n{stderr}"
    m = re.search(r": (\d+) run, (\d+) skipped \(finished before\), (\d+) failed, (\d+) left to other processes", stdout)
    assert m, f"no summary line:\n{stdout}"
    ran_total += int(m.group(1))
    ran_points += re.findall(r"\] dem_stokes Mn=\S+ seed \d+ -> \S+/(dem_stokes/\S+)", stderr)
    print(f"one process: {m.group(0)[2:]}")
assert ran_total == 4, f"{ran_total} runs for 4 points"
assert sorted(ran_points) == sorted(set(ran_points)) and len(ran_points) == 4, ran_points
assert saw_running, "--list never called a point running while two sweeps ran"
alone = work / "alone"
subprocess.run([mrf, "sweep", str(sweep), "--out", str(alone), "--quiet"], check=True, capture_output=True)
for d in ran_points:
    a = json.loads((out / d / "summary.json").read_text())["stress_total"]
    b = json.loads((alone / d / "summary.json").read_text())["stress_total"]
    assert a == b, f"{d}: {a} shared against {b} alone"
print("SweepClaims: 4 points, each run once by one of two processes, as run alone; --list saw a point running")
