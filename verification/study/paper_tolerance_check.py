#!/usr/bin/env python3
"""ctest PaperTolerance: the rule of reports/paper_tolerance.py (fixed in
experiments/sweeps/paper_tolerance.toml) on synthetic runs of model 1's
design, whose bias against the finest tolerance is known:

- bias -8 Pa x (t - t_ref), paired noise 0.005 Pa, run errors 0.06 Pa
  (T = 0.03): 1e-2 and 5e-3 fail, 2.5e-3 and 1.25e-3 pass -> 2.5e-3;
- the same bias with the opposite sign: the same choice;
- a bias at Mn 10 only at the default (the rest clean): 5e-3 is the
  loosest passing at both Mn;
- 2.5e-3 passing and 1.25e-3 failing at one Mn: no tolerance has every
  tighter one passing -> inconclusive;
- paired noise 0.1 Pa (SE 0.04, so |b| + 2 SE > T everywhere): inconclusive;
- one run missing: incomplete;
and the report and figure are written (the coupled design's runs absent:
"not yet evaluable").

Usage: paper_tolerance_check.py WORKDIR
"""
import importlib.util
import json
import os
import pathlib
import random
import shutil
import subprocess
import sys

try:  # the report draws with matplotlib: this interpreter, or the system one the report scripts name
    import matplotlib  # noqa: F401
except ImportError:
    os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)

root = pathlib.Path(__file__).resolve().parents[2]
work = pathlib.Path(sys.argv[1])
spec = importlib.util.spec_from_file_location("paper_tolerance", root / "reports" / "paper_tolerance.py")
pt = importlib.util.module_from_spec(spec)
spec.loader.exec_module(pt)
design = pt.DESIGNS[0]
assert design.model == "dem_stokes" and design.ref == min(design.tols), design.tols


def make(bias, noise, skip=None, seed=1):
    """Runs under work/paper/<archive>: stress = 102 + seed offset + bias(mn, t) + paired noise."""
    rng = random.Random(seed)
    shutil.rmtree(work, ignore_errors=True)
    points = work / "paper" / design.archive
    for mn in design.mason:
        for s in design.seeds:
            base = 102.0 + 0.1 * s  # the seed scatter, which the pairing removes
            for t in design.tols:
                if (mn, s, t) == skip:
                    continue
                d = points / design.model / f"tol_{t:g}" / f"mn_{mn:g}_seed_{s}"
                d.mkdir(parents=True)
                stress = base + bias(mn, t) + (rng.gauss(0.0, noise) if t != design.ref else 0.0)
                (d / "summary.json").write_text(json.dumps({
                    "stress_total": stress, "stress_total_err": 0.06, "stress_total_drift_z": 0.5,
                    "steady_mser_discard_fraction": 0.05, "steps": int(10 / t), "wall_seconds": 1.0 / t}))
    return points


def chosen(bias, noise=0.005, skip=None):
    runs, rows, thresholds = pt.analyse(design, make(bias, noise, skip))
    assert skip or all(abs(thresholds[mn] - 0.03) < 1e-12 for mn in design.mason), thresholds
    return pt.choose(design, rows)


ref = design.ref
linear = lambda mn, t: -8.0 * (t - ref)  # noqa: E731
got = chosen(linear)
assert got == 2.5e-3, got
print("bias -8 (t - t_ref): 2.5e-3")

got = chosen(lambda mn, t: -linear(mn, t))
assert got == 2.5e-3, got
print("the same bias, positive: 2.5e-3")

got = chosen(lambda mn, t: -0.1 if (mn == 10.0 and t == 1e-2) else 0.0)
assert got == 5e-3, got
print("a bias at Mn 10 at the default only: 5e-3")

got = chosen(lambda mn, t: -0.05 if (mn == 1.0 and t == 1.25e-3) else linear(mn, t))
assert got == "inconclusive", got
print("1.25e-3 failing, 2.5e-3 passing at Mn 1: inconclusive")

got = chosen(linear, noise=0.1)
assert got == "inconclusive", got
print("paired noise 0.1 Pa: inconclusive")

got = chosen(linear, skip=(10.0, 3, 5e-3))
assert got == "incomplete", got
print("one run missing: incomplete")

# the whole report on the first case: written, with the choice and the coupled design not yet evaluable
make(linear, 0.005)
r = subprocess.run([sys.executable, str(root / "reports" / "paper_tolerance.py"), str(work / "paper")],
                   capture_output=True, text=True)
assert r.returncode == 0, r.stderr
text = (work / "paper" / "tolerance.md").read_text()
assert "**Chosen tolerance: 0.0025**" in text and "Rule not yet evaluable" in text, text[:2000]
assert (work / "paper" / "tolerance.png").stat().st_size > 1000
print("report and figure written")
