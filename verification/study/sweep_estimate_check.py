#!/usr/bin/env python3
"""ctest SweepEstimate: `mrf sweep --estimate` on a 2-point sweep of model 1
(Mn 0.3 and 1, strain 0.2), what `scripts/reproduce paper --estimate` reads.

- Before anything ran: 2 of 2 points to run, and the "to run" seconds are
  the total's.
- After point 0 ran: its line says (finished) with its own wall seconds as
  the estimate; 1 of 2 points to run, and the "to run" seconds are point
  1's estimate alone.
- The same from the archive alone (the output folder removed), which the
  estimate reads where it is: it writes nothing into --out; nor does
  --list, which calls point 0 "archived".
- After a rule doubles point 0's strain (its run is now for another scene):
  2 of 2 to run, and point 0 is estimated by its own earlier run's seconds
  per strain unit times the new strain (not by its old wall time); --list
  calls it "stale".
- A run under way (a checkpoint and series rows up to strain 0.05 of 0.2):
  its line says how far it has come, the "to run" seconds count only the
  rest of its strain (0.75 of its estimate), and --list says "started" with
  its strain; without a checkpoint (a run that would start again) its whole
  estimate counts.
- `--collect --archive` over an output that holds a finished run of
  another scene (a rule since reverted) tabulates the archive's run of this
  scene, and keeps the other aside.

Usage: sweep_estimate_check.py MRF_BINARY SCENE WORKDIR
"""
import json, pathlib, re, shutil, subprocess, sys

mrf, scene, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
HEAD = f"""[sweep]
scene = "{scene}"
models = ["dem_stokes"]
mason = [0.3, 1.0]
seeds = [1]
set = ["drive.strain=0.2", "drive.warmup_strain=0.05", "numerics.threads=1"]
"""
sweep = work / "tiny.toml"
sweep.write_text(HEAD)
out, archive = work / "out", work / "archive"


def estimate(*extra):
    text = subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--estimate", *extra], check=True,
                          capture_output=True, text=True).stdout
    lines = text.strip().splitlines()
    per = {}
    for ln in lines[:-2]:
        m = re.match(r"(\S+)\s+estimated (\S+) s", ln)
        per[m.group(1)] = (float(m.group(2)), "(finished)" in ln)
    run = re.match(r"to run (\S+) s \(\S+ h\) on one core: (\d+) of (\d+) points", lines[-2])
    tot = re.match(r"total (\S+) s", lines[-1])
    assert run and tot, f"unexpected estimate output:\n{text}"
    return per, float(run.group(1)), int(run.group(2)), int(run.group(3)), float(tot.group(1))


def list_states(*extra):
    text = subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--list", *extra], check=True,
                          capture_output=True, text=True).stdout
    return {f[1]: f[5] for f in (ln.split() for ln in text.strip().splitlines()[1:])}


def close(a, b):
    return abs(a - b) <= 1e-2 * max(abs(a), abs(b))


p0, p1 = "dem_stokes/mn_0.3_seed_1", "dem_stokes/mn_1_seed_1"
per, left, n_run, n, total = estimate()
assert (n_run, n) == (2, 2) and close(left, total), (n_run, n, left, total)
assert not per[p0][1] and not per[p1][1]
print(f"nothing run: 2 of 2 to run, {left:.3g} s = the total")

subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--archive", str(archive), "--point", "0", "--quiet"],
               check=True, capture_output=True)
s0 = json.loads((out / p0 / "summary.json").read_text())
for extra in ((), ("--archive", str(archive))):
    if extra:
        shutil.rmtree(out)
    per, left, n_run, n, total = estimate(*extra)
    assert per[p0][1] and not per[p1][1], per
    assert (n_run, n) == (1, 2), (n_run, n)
    assert close(left, per[p1][0]), (left, per[p1][0])
    if not extra:  # a point finished in --out is its own estimate
        assert close(per[p0][0], s0["wall_seconds"]), (per[p0][0], s0["wall_seconds"])
    else:  # read where it is: an estimate writes nothing into --out, nor does a list
        assert not out.exists(), "--estimate --archive restored the archive into --out"
        assert list_states(*extra) == {p0: "archived", p1: "todo"}, list_states(*extra)
        assert not out.exists(), "--list --archive restored the archive into --out"
    print(f"point 0 finished ({'archive' if extra else 'output'}): 1 of 2 to run, {left:.3g} s = point 1's estimate")

# point 0 run again into --out, then a rule doubles its strain: stale
subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--point", "0", "--quiet"], check=True,
               capture_output=True)
s0 = json.loads((out / p0 / "summary.json").read_text())
sweep.write_text(HEAD + '\n[[rule]]\nmason_max = 0.5\nset = ["drive.strain=0.4", "drive.warmup_strain=0.1"]\n')
per, left, n_run, n, total = estimate()
assert (n_run, n) == (2, 2), (n_run, n)
assert not per[p0][1], "a run for another scene does not count as finished"
assert list_states()[p0] == "stale", list_states()
shutil.rmtree(out)  # the archive's entry of point 0 is for the old strain: stale there too
assert list_states("--archive", str(archive)) == {p0: "stale", p1: "todo"}, list_states("--archive", str(archive))
want = s0["seconds_per_strain"] * 0.4
assert close(per[p0][0], want), f"stale point 0 estimated {per[p0][0]} s, want its own {s0['seconds_per_strain']} s per strain x 0.4"
print(f"rule changed point 0's strain: 2 of 2 to run, point 0 at its own rate x new strain ({per[p0][0]:.3g} s)")

# point 1 under way: a checkpoint (its content is the run's business) and series rows up to strain 0.05
shutil.rmtree(out, ignore_errors=True)
sweep.write_text(HEAD)
subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--point", "0", "--quiet"], check=True,
               capture_output=True)
rows = (out / p0 / "timeseries.csv").read_text().splitlines()
kept = [rows[0]] + [r for r in rows[1:] if float(r.split(",")[1]) <= 0.05]
reached = float(kept[-1].split(",")[1])
assert len(kept) > 2 and reached > 0.02, kept
(out / p1).mkdir(parents=True)
(out / p1 / "timeseries.csv").write_text("\n".join(kept) + "\n")
per, whole, n_run, n, total = estimate()
assert (n_run, n) == (1, 2), (n_run, n)
assert close(whole, per[p1][0]), "without a checkpoint the run starts again: its whole estimate is to run"
(out / p1 / "checkpoint.bin").write_bytes(b"a run's checkpoint")
text = subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--estimate"], check=True, capture_output=True,
                      text=True).stdout
per, left, n_run, n, total = estimate()
assert (n_run, n) == (1, 2), (n_run, n)
assert close(left, per[p1][0] * (1 - reached / 0.2)), (left, per[p1][0], reached)
assert f"started: strain {reached:.3g} of 0.2" in text, text
listed = subprocess.run([mrf, "sweep", str(sweep), "--out", str(out), "--list"], check=True, capture_output=True,
                        text=True).stdout
line = next(ln for ln in listed.splitlines() if p1 in ln)
assert line.split()[5] == "started" and f"(strain {reached:.3g} of 0.2)" in line, line
print(f"point 1 under way at strain {reached:.3g} of 0.2: {left:.3g} s to run of its {per[p1][0]:.3g} s")

# --collect --archive where --out holds a finished run of another scene (a rule since reverted) and the
# archive a current one: the other scene's run is set aside and the archived one tabulated, as a run would
out2 = work / "out2"
sweep.write_text(HEAD + '\n[[rule]]\nmason_max = 0.5\nset = ["drive.strain=0.4", "drive.warmup_strain=0.1"]\n')
subprocess.run([mrf, "sweep", str(sweep), "--out", str(out2), "--point", "0", "--quiet"], check=True,
               capture_output=True)
sweep.write_text(HEAD)
subprocess.run([mrf, "sweep", str(sweep), "--out", str(out2), "--archive", str(archive), "--collect", "--quiet"],
               check=True, capture_output=True)
table = {r.split(",")[-1]: r.split(",") for r in (out2 / "sweep.csv").read_text().splitlines()[1:]}
head = (out2 / "sweep.csv").read_text().splitlines()[0].split(",")
row = table[p0]
assert row[head.index("status")] == "ok" and float(row[head.index("strain")]) == 0.2, row
assert list(out2.glob("dem_stokes/mn_0.3_seed_1.stale-*/summary.json")), "the other scene's run was not kept aside"
print("--collect --archive: another scene's run in --out set aside, the archived run of this scene tabulated")
print("SweepEstimate: ok")
