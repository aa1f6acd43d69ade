#!/usr/bin/env python3
"""ctest PaperCheck: scripts/paper_check.py's verdicts on runs made from the
archived summaries themselves.

- every new run a copy of its archived run: all reproduce (z = 0), passes (0);
- one point's stress moved by 5 combined deviations: that point fails, the
  check fails (1); moved by 2: it still passes;
- one new run unsteady (drift z 4): the check fails (1);
- one point not run: not finished (3).

Usage: paper_check_check.py WORKDIR
"""
import json, math, pathlib, shutil, statistics, subprocess, sys

root = pathlib.Path(__file__).resolve().parents[2]
work = pathlib.Path(sys.argv[1])
archive = root / "reports" / "study" / "paper" / "points"
points = [ln.strip() for ln in (root / "experiments" / "sweeps" / "paper_check.txt").read_text().splitlines()
          if ln.strip() and not ln.startswith("#")]
assert len(points) == 11, points


def make_runs():
    shutil.rmtree(work, ignore_errors=True)
    for p in points:
        (work / "runs" / p).mkdir(parents=True)
        shutil.copy(archive / p / "summary.json", work / "runs" / p / "summary.json")


def check():
    r = subprocess.run([sys.executable, str(root / "scripts" / "paper_check.py"), "--runs", str(work / "runs"),
                        "--out", str(work / "check.md")], capture_output=True, text=True)
    return r.returncode, (work / "check.md").read_text()


def edit(p, **kv):
    f = work / "runs" / p / "summary.json"
    s = json.loads(f.read_text())
    s.update(kv)
    f.write_text(json.dumps(s))
    return s


make_runs()
status, text = check()
assert status == 0 and "**passes**: 11 of 11" in text, (status, text)
print("copies of the archived runs: passes")

p = "demsph_dd/mn_0.01_seed_1"
stem = p.rsplit("_seed_", 1)[0]
old = json.loads((archive / p / "summary.json").read_text())
sd = statistics.stdev(json.loads(f.read_text())["stress_total"] for f in archive.glob(stem + "_seed_*/summary.json"))
s = max(old["stress_total_err"], sd) * math.sqrt(2)  # both runs carry the same errors here
for k, want in ((5, 1), (2, 0)):
    make_runs()
    edit(p, stress_total=old["stress_total"] + k * s)
    status, text = check()
    assert status == want, (k, status, text)
    assert (f"| {p} |" in text) and ((" (fails)" in text) == (want == 1)), text
print("a stress moved by 5 combined deviations fails, by 2 passes")

make_runs()
edit("dem_stokes/mn_0.01_seed_1", stress_total_drift_z=4.0)
status, text = check()
assert status == 1 and "| no (+4.00" in text, (status, text)
print("an unsteady new run fails the check")

make_runs()
shutil.rmtree(work / "runs" / "dem_stokes" / "mn_10_seed_1")
status, text = check()
assert status == 3 and "10 of 11 points run so far" in text and "not run yet" in text, (status, text)
print("a point not run yet: not finished")
print("PaperCheck: ok")
