#!/usr/bin/env python3
"""ctest QuasistaticCli: `mrf quasistatic` on the small scene (Y = 2 GPa, five
increments of 1e-3): exit 0, quasistatic.csv with one row per minimum (the
initial one and five more), every minimum below the force tolerance, wall and
virial stress equal within the static-equilibrium bound, and summary.json
with the steady mean, its error and the scene's id. Then the checkpoint:
the same --out without --resume is refused (exit 2); --resume with
--strain 0.007 extends the finished run by two minima and leaves the first
six rows as they were; --resume with another increment is refused (exit 3,
naming quasistatic.strain_increment). Then the minimisers: --minimiser lbfgs
names itself in summary.json and meets the same checks; an unknown minimiser
is refused (exit 2, naming --minimiser); --start-from a file that is not a
frames file is refused (exit 2, naming --start-from and the line).

Usage: cli_check.py MRF_BINARY SCENE WORKDIR
"""
import csv, json, pathlib, shutil, subprocess, sys

mrf, scene, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
base = [mrf, "quasistatic", scene, "--set", "contact.youngs_modulus=2e9", "--warmup", "0.002", "--out", str(work),
        "--quiet"]
subprocess.run(base + ["--strain", "0.005", "--increment", "1e-3"], check=True)
s = json.loads((work / "summary.json").read_text())
rows = list(csv.DictReader((work / "quasistatic.csv").open()))
bad = []
if len(rows) != 6 or s["minima"] != 6:
    bad.append(f"expected 6 minima, got {len(rows)} rows and minima = {s['minima']}")
for r in rows:
    if float(r["max_force"]) >= s["force_tol"]:
        bad.append(f"strain {r['strain']}: max |f| {r['max_force']} >= tol {s['force_tol']}")
    if abs(float(r["stress_wall"]) - float(r["stress_virial"])) > s["equilibrium_bound"]:
        bad.append(f"strain {r['strain']}: wall {r['stress_wall']} and virial {r['stress_virial']} differ beyond "
                   f"{s['equilibrium_bound']}")
if abs(float(rows[-1]["strain"]) - 0.005) > 1e-12:
    bad.append(f"last strain {rows[-1]['strain']}")
for k in ("stress_wall", "stress_wall_err", "stress_virial", "scene_id", "stress_wall_over_phi_mu0_m2",
          "orbit_period_strain", "orbit_periodic"):
    if k not in s:
        bad.append(f"summary.json lacks {k}")
# 5 increments of 1e-3 are far shorter than two periods lz/gap = 0.4: no orbit is claimed.
if s.get("orbit_periodic") is not False or abs(s.get("orbit_period_strain", 0) - 32.0 / 80.0) > 1e-12:
    bad.append(f"orbit: periodic {s.get('orbit_periodic')}, period {s.get('orbit_period_strain')}")
first_rows = (work / "quasistatic.csv").read_text().splitlines()
again = subprocess.run(base + ["--strain", "0.005", "--increment", "1e-3"], capture_output=True, text=True)
if again.returncode != 2 or "--resume" not in again.stderr:
    bad.append(f"a second run into the same --out: exit {again.returncode}, stderr {again.stderr.strip()!r}")
ext = subprocess.run(base + ["--strain", "0.007", "--increment", "1e-3", "--resume"], capture_output=True, text=True)
ext_rows = (work / "quasistatic.csv").read_text().splitlines()
if ext.returncode != 0 or len(ext_rows) != 9 or ext_rows[:7] != first_rows:
    bad.append(f"--resume --strain 0.007: exit {ext.returncode}, {len(ext_rows) - 1} rows, first rows kept: "
               f"{ext_rows[:7] == first_rows}; {ext.stderr.strip()}")
if json.loads((work / "summary.json").read_text())["minima"] != 8:
    bad.append("summary.json of the extended run does not count 8 minima")
other = subprocess.run(base + ["--strain", "0.007", "--increment", "5e-4", "--resume"], capture_output=True, text=True)
if other.returncode != 3 or "quasistatic.strain_increment" not in other.stderr:
    bad.append(f"--resume with another increment: exit {other.returncode}, stderr {other.stderr.strip()!r}")
lb = work.parent / (work.name + "_lbfgs")
shutil.rmtree(lb, ignore_errors=True)
lb_base = base[:base.index("--out")] + ["--out", str(lb), "--quiet", "--strain", "0.003", "--increment", "1e-3"]
run = subprocess.run(lb_base + ["--minimiser", "lbfgs"], capture_output=True, text=True)
if run.returncode != 0:
    bad.append(f"--minimiser lbfgs: exit {run.returncode}, {run.stderr.strip()}")
else:
    ls = json.loads((lb / "summary.json").read_text())
    lrows = list(csv.DictReader((lb / "quasistatic.csv").open()))
    if ls.get("minimiser") != "lbfgs" or "L-BFGS" not in ls.get("driver", "") or len(lrows) != 4:
        bad.append(f"--minimiser lbfgs: minimiser {ls.get('minimiser')!r}, driver {ls.get('driver')!r}, {len(lrows)} rows")
    for r in lrows:
        if float(r["max_force"]) >= ls["force_tol"] or \
                abs(float(r["stress_wall"]) - float(r["stress_virial"])) > ls["equilibrium_bound"]:
            bad.append(f"--minimiser lbfgs, strain {r['strain']}: not a minimum in equilibrium")
shutil.rmtree(lb, ignore_errors=True)
unknown = subprocess.run(lb_base + ["--minimiser", "cg"], capture_output=True, text=True)
if unknown.returncode != 2 or "--minimiser" not in unknown.stderr:
    bad.append(f"--minimiser cg: exit {unknown.returncode}, stderr {unknown.stderr.strip()!r}")
junk = work.parent / (work.name + "_junk.xyz")
junk.write_text("2\nTime=0\nFe 0 0 0 2.5e-6\n")
shutil.rmtree(lb, ignore_errors=True)
start = subprocess.run(lb_base + ["--start-from", str(junk)], capture_output=True, text=True)
if start.returncode != 2 or "--start-from" not in start.stderr or "line 3" not in start.stderr:
    bad.append(f"--start-from a short frame: exit {start.returncode}, stderr {start.stderr.strip()!r}")
print("\n".join(bad) if bad else f"mrf quasistatic: {len(rows)} minima, all checks passed")
sys.exit(1 if bad else 0)
