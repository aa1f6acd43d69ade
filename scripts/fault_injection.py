#!/usr/bin/env python3
"""Fault injection (issue: sweeps on a real distributed engine, and
reliability proven by fault injection).

A. A 4-point sweep (small scene, models dem_stokes and demsph_dd, Mn 0.3 and
   1, checkpoints every 0.2 s) is killed with SIGKILL at random moments
   KILLS times (default 20), restarted after each kill, then left to finish;
   its sweep.csv is compared field by field (timing fields aside) with an
   uninterrupted sweep of the same file.
B. A checkpoint left by a killed run is corrupted (bytes flipped at random
   offsets, truncated at random lengths, replaced by a foreign file, emptied)
   and `mrf run --resume` must refuse every one, naming the checkpoint; the
   intact copy must resume.

Prints a table and writes reports/reliability/fault_injection.md.
Usage: scripts/fault_injection.py [MRF_BINARY] [--kills N] [--seed S] [--report FILE]
(ctest label slow runs it with the report in the build directory.)
Exit status 1 if anything did not survive.
"""
import csv, os, pathlib, random, shutil, signal, subprocess, sys, time

root = pathlib.Path(__file__).resolve().parent.parent
args = sys.argv[1:]
def opt(name, default):
    if name in args:
        i = args.index(name)
        v = args[i + 1]
        del args[i:i + 2]
        return type(default)(v)
    return default
kills = opt("--kills", 20)
report = pathlib.Path(opt("--report", str(root / "reports" / "reliability" / "fault_injection.md")))
seed = opt("--seed", 1)
mrf = str(pathlib.Path(args[0]).resolve()) if args else str(root / "build" / "mrf")
rng = random.Random(seed)
out = root / "out" / "fault_injection"
shutil.rmtree(out, ignore_errors=True)
out.mkdir(parents=True)
scene = root / "experiments" / "scenes" / "small_dem_stokes.toml"
env = dict(os.environ, OMP_NUM_THREADS="1")

sweep = out / "sweep.toml"
sweep.write_text(f"""[sweep]
scene = "{scene}"
models = ["dem_stokes", "demsph_dd"]
mason = [0.3, 1.0]
seeds = [1]
set = ["drive.strain=3", "drive.warmup_strain=1", "numerics.threads=1"]
""")


def sweep_cmd(dest):
    return [mrf, "sweep", str(sweep), "--out", str(dest), "--quiet", "--checkpoint-every", "0.2"]


def rows(dest):
    with open(dest / "sweep.csv") as f:
        return list(csv.DictReader(f))


timing = lambda k: "second" in k or k.endswith("_per_second") or k == "threads"

# A. kills
t0 = time.monotonic()
subprocess.run(sweep_cmd(out / "reference"), check=True, env=env, stdout=subprocess.DEVNULL)
ref_seconds = time.monotonic() - t0
killed, landed_mid_run, runs = 0, 0, 0
dest = out / "killed"
while killed < kills:
    p = subprocess.Popen(sweep_cmd(dest), env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    runs += 1
    try:
        p.wait(timeout=rng.uniform(0.3, 0.3 + ref_seconds / 3))
        if (dest / "sweep.csv").exists() and len(rows(dest)) == 4:
            shutil.rmtree(dest)  # finished before the kill: start over, so every kill lands in a run
        continue
    except subprocess.TimeoutExpired:
        pass
    mid = any(dest.glob("*/*/checkpoint.bin"))
    p.send_signal(signal.SIGKILL)
    p.wait()
    killed += 1
    landed_mid_run += 1 if mid else 0
subprocess.run(sweep_cmd(dest), check=True, env=env, stdout=subprocess.DEVNULL)
a, b = rows(out / "reference"), rows(dest)
fields = [k for k in a[0] if not timing(k)]
diff = [(ra["model"], ra["mason"], k, ra[k], rb[k]) for ra, rb in zip(a, b) for k in fields if ra[k] != rb[k]]
same = len(a) == len(b) == 4 and not diff

# B. corrupted checkpoints
run_dir = out / "run"
cmd = [mrf, "run", str(scene), "--quiet", "--out", str(run_dir), "--checkpoint-every", "0.2", "--resume",
       "--set", 'scene.model="demsph_dd"', "--set", "drive.mason=1", "--set", "drive.strain=3",
       "--set", "drive.warmup_strain=1"]
p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
ck = run_dir / "checkpoint.bin"
for _ in range(200):
    time.sleep(0.05)
    if ck.exists() and ck.stat().st_size > 0:
        time.sleep(0.3)
        break
p.send_signal(signal.SIGKILL)
p.wait()
good = ck.read_bytes()
cases = []
for k in range(6):
    b2 = bytearray(good)
    pos = rng.randrange(len(b2))
    b2[pos] ^= 1 << rng.randrange(8)
    cases.append((f"bit flip at byte {pos} of {len(good)}", bytes(b2)))
for k in range(3):
    n = rng.randrange(len(good))
    cases.append((f"truncated to {n} of {len(good)} bytes", good[:n]))
cases.append(("foreign file (a scene)", scene.read_bytes()))
cases.append(("empty file", b""))
cases.append(("intact, but its timeseries.csv deleted", good))
series = (run_dir / "timeseries.csv").read_bytes()
results = []
for what, data in cases:
    d = out / "corrupt"
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir()
    (d / "checkpoint.bin").write_bytes(data)
    if "deleted" not in what:
        (d / "timeseries.csv").write_bytes(series)
    r = subprocess.run([c if c != str(run_dir) else str(d) for c in cmd], env=env, capture_output=True, text=True)
    msg = (r.stderr.strip().splitlines() or [""])[-1].replace(str(root) + "/", "")
    refused = r.returncode != 0 and "checkpoint" in msg.lower()
    results.append((what, refused, msg))
d = out / "intact"
shutil.rmtree(d, ignore_errors=True)
d.mkdir()
(d / "checkpoint.bin").write_bytes(good)
(d / "timeseries.csv").write_bytes(series)
r = subprocess.run([c if c != str(run_dir) else str(d) for c in cmd], env=env, capture_output=True, text=True)
intact_ok = r.returncode == 0 and (d / "summary.json").exists()

# most kills must land with a checkpoint on disk (a kill before the first
# checkpoint of a point restarts that point from its start, also tested)
ok = same and all(x[1] for x in results) and intact_ok and 2 * landed_mid_run >= kills
lines = ["# Fault injection", "",
         f"Generated by `scripts/fault_injection.py` (seed {seed}) on {os.uname().nodename}, {time.strftime('%Y-%m-%d')}.", "",
         "## A. SIGKILL during a sweep", "",
         f"4 points (small scene; dem_stokes and demsph_dd at Mn 0.3 and 1; strain 3), checkpoints every 0.2 s; "
         f"uninterrupted sweep {ref_seconds:.1f} s.", "",
         "| kills | kills with a checkpoint on disk | restarts | sweep.csv equal to the uninterrupted one |",
         "|---|---|---|---|",
         f"| {killed} | {landed_mid_run} | {runs} | {'yes, ' + str(len(fields)) + ' fields x 4 rows' if same else 'NO'} |", ""]
if diff:
    lines += ["Differences:", ""] + [f"- {m} Mn {mn} {k}: {x} vs {y}" for m, mn, k, x, y in diff[:20]] + [""]
lines += ["## B. Damaged checkpoints (`mrf run --resume`)", "",
          "| damage | refused | message |", "|---|---|---|"]
lines += [f"| {w} | {'yes' if ok_ else 'NO'} | {m.replace('|', '/')} |" for w, ok_, m in results]
lines += [f"| none (control) | {'resumed and finished' if intact_ok else 'FAILED'} | |", "",
          f"Overall: {'everything survived' if ok else 'FAILURES above'}."]
text = "\n".join(lines) + "\n"
report.write_text(text)
print(text)
sys.exit(0 if ok else 1)
