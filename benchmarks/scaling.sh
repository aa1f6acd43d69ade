#!/usr/bin/env bash
# Single-run scaling of mrf: time per step and per particle-step against N,
# peak memory against N, and 1 against 2 OpenMP threads (docs/scaling.md).
#
#   benchmarks/scaling.sh [--mrf PATH] [--reps N] [--work DIR] [--quick] [--no-mn3]
#   benchmarks/scaling.sh --help
#
# Prints a markdown report (header, one table row per run, fits, speed-ups)
# on stdout; redirect it to keep it (reports/performance/scaling.md is one
# such output). Never builds; every run goes to --work (default
# ${TMPDIR:-/tmp}/mrf-scaling). Runs are sequential; only the 2-thread runs
# use 2 cores. Needs python3 (JSON and fits) and, for the peak RSS,
# /usr/bin/time (package `time`); without it python's wait4 rusage is used.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'EOF'
benchmarks/scaling.sh: measured single-run scaling of mrf (docs/scaling.md)

Options:
  --mrf PATH          mrf binary (default: $MRF, else build/mrf)
  --reps N            repetitions of every timing (default 2; each is reported)
  --work DIR          scratch output directories (default ${TMPDIR:-/tmp}/mrf-scaling)
  --sections LIST     comma-separated, from: size, threads, long, mn3, big, ckpt
                      (default size,threads,long,mn3; big is the 16x cell, ~100 s a run)
  --quick             size and threads on the small and paper cells only (about 1 minute)
  --autogroup-nice N  run in a new session whose scheduler autogroup has nice N
                      (Linux sched_autogroup; negative N needs root). On a machine
                      shared with niced jobs of another session, autogroup splits the
                      CPU per session, so those jobs still take half of it and a
                      2-thread run gets about one core; see docs/scaling.md
  -h, --help          this text

What runs (scenes from experiments/scenes/, their own Mn = 1e-2 at fixed
magnetisation 1 MA/m, Y = 200 GPa, so `auto` picks the implicit inertialess
scheme; warm-up 0 from the random start, strain 0.5 for model 1 and 0.25
for model 3):
  size:    model 1 (dem_stokes), 1 thread: small cell (375 spheres), paper
           cell (4125), paper 2x (ly 100 um), 4x (ly 100, lz 240 um), 8x (ly 200,
           lz 240 um); model 3 (demsph_dd): small, paper, paper 2x, paper 4x
  threads: paper cell (models 1 and 3) and paper 4x (model 1) at 1 and 2
           threads, the 1- and 2-thread runs alternated
  long:    model 1, paper cell to strain 2 (chains formed)
  mn3:     model 1, paper cell at Mn = 1e-3 (strain 0.25)
  big:     model 1, paper 16x (ly 200, lz 480 um, 66000 spheres)
  ckpt:    model 1, paper 4x with a checkpoint every 5 s (its peak RSS against the 4x row)
Every other run has --checkpoint-every 0: a checkpoint holds the whole state,
Verlet lists included, in memory while it is written, which raises the peak RSS.
Each run's summary.json gives wall_seconds (time-step loop only), steps,
N and the implicit iteration counts; peak RSS is the process's max RSS.
Fits over the paper-cell family (1 thread, same strain, mean of the reps):
log(time per step) and log(seconds per strain) against log(N); RSS = a + b N.
EOF
}

MRF=${MRF:-build/mrf}
REPS=2
WORK=${TMPDIR:-/tmp}/mrf-scaling
QUICK=0
SECTIONS=size,threads,long,mn3
AGNICE=""
ARGS=("$@")
while [ $# -gt 0 ]; do
  case "$1" in
    --mrf) MRF=$2; shift 2 ;;
    --reps) REPS=$2; shift 2 ;;
    --work) WORK=$2; shift 2 ;;
    --quick) QUICK=1; shift ;;
    --sections) SECTIONS=$2; shift 2 ;;
    --autogroup-nice) AGNICE=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "scaling.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [ -n "$AGNICE" ] && [ -z "${MRF_SCALING_SESSION:-}" ]; then
  # a new session gets its own autogroup; set its nice, then run this script in it
  exec setsid env MRF_SCALING_SESSION=1 bash -c 'echo "$1" >/proc/self/autogroup && shift && exec "$@"' \
    _ "$AGNICE" "$0" "${ARGS[@]}"
fi
has() { case ",$SECTIONS," in *",$1,"*) return 0 ;; *) return 1 ;; esac; }
[ -x "$MRF" ] || { echo "scaling.sh: no mrf binary at '$MRF' (give --mrf PATH)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "scaling.sh: needs python3" >&2; exit 2; }
mkdir -p "$WORK"
RUNS=$WORK/runs.tsv
: >"$RUNS"
SC=experiments/scenes

# run LABEL MODEL CELL THREADS SCENE STRAIN [--set ...]: one run, one line in runs.tsv
run() {
  local label=$1 model=$2 cell=$3 threads=$4 scene=$5 strain=$6 rep=$7
  shift 7
  local dir=$WORK/$label.r$rep
  local tfile=$dir.time
  rm -rf "$dir"
  local cmd=("$MRF" run "$SC/$scene" --quiet --out "$dir" --checkpoint-every "${CKPT_EVERY:-0}" --set drive.strain="$strain"
             --set drive.warmup_strain=0 --set numerics.threads="$threads" "$@")
  if [ -x /usr/bin/time ]; then
    OMP_NUM_THREADS=$threads /usr/bin/time -v -o "$tfile" "${cmd[@]}" >/dev/null
    rss=$(awk -F: '/Maximum resident set size/{gsub(/ /,"",$2); print $2}' "$tfile")
    cpu=$(awk -F: '/Percent of CPU this job got/{gsub(/ /,"",$2); print $2}' "$tfile")
  else
    cpu=n/a
    rss=$(OMP_NUM_THREADS=$threads python3 -c '
import os, sys
pid = os.fork()
if pid == 0:
    fd = os.open(os.devnull, os.O_WRONLY); os.dup2(fd, 1)
    os.execvp(sys.argv[1], sys.argv[1:])
_, status, ru = os.wait4(pid, 0)
if status: sys.exit(1)
print(ru.ru_maxrss)' "${cmd[@]}")
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$label" "$model" "$cell" "$threads" "$rep" "$rss" "$cpu" "$dir/summary.json" >>"$RUNS"
  echo "  done $label rep $rep (max RSS ${rss} kB)" >&2
}

X2=(--set 'box.ly="100 um"')
X4=(--set 'box.ly="100 um"' --set 'box.lz="240 um"')
X8=(--set 'box.ly="200 um"' --set 'box.lz="240 um"')
MN3SET=(--set drive.mason=1e-3)

started=$(date -u '+%Y-%m-%d %H:%M UTC')
load0=$(cut -d' ' -f1-3 /proc/loadavg)
X16=(--set 'box.ly="200 um"' --set 'box.lz="480 um"')
for rep in $(seq "$REPS"); do
  echo "repetition $rep of $REPS" >&2
  if has size; then
    run m1_small  dem_stokes small 1 small_dem_stokes.toml 0.5 "$rep"
    run m1_paper  dem_stokes paper 1 paper_dem_stokes.toml 0.5 "$rep"
    run m3_small  demsph_dd  small 1 small_demsph_dd.toml 0.5 "$rep"
    run m3_paper  demsph_dd  paper 1 paper_demsph_dd.toml 0.25 "$rep"
  fi
  if has threads; then  # 1 and 2 threads side by side, the order alternated between repetitions
    for t in $( [ $((rep % 2)) -eq 1 ] && echo "2 1" || echo "1 2"); do
      run m1_paper_t$t dem_stokes paper "$t" paper_dem_stokes.toml 0.5 "$rep"
      run m3_paper_t$t demsph_dd  paper "$t" paper_demsph_dd.toml 0.25 "$rep"
    done
  fi
  [ "$QUICK" = 1 ] && continue
  if has size; then
    run m1_paper2x dem_stokes paper2x 1 paper_dem_stokes.toml 0.5 "$rep" "${X2[@]}"
    run m1_paper4x dem_stokes paper4x 1 paper_dem_stokes.toml 0.5 "$rep" "${X4[@]}"
    run m1_paper8x dem_stokes paper8x 1 paper_dem_stokes.toml 0.5 "$rep" "${X8[@]}"
    run m3_paper2x demsph_dd  paper2x 1 paper_demsph_dd.toml 0.25 "$rep" "${X2[@]}"
    run m3_paper4x demsph_dd  paper4x 1 paper_demsph_dd.toml 0.25 "$rep" "${X4[@]}"
  fi
  if has threads; then
    for t in $( [ $((rep % 2)) -eq 1 ] && echo "1 2" || echo "2 1"); do
      run m1_paper4x_t$t dem_stokes paper4x "$t" paper_dem_stokes.toml 0.5 "$rep" "${X4[@]}"
    done
  fi
  if has big; then run m1_paper16x dem_stokes paper16x 1 paper_dem_stokes.toml 0.5 "$rep" "${X16[@]}"; fi
  if has ckpt; then CKPT_EVERY=5 run m1_paper4x_ckpt5s dem_stokes paper4x 1 paper_dem_stokes.toml 0.5 "$rep" "${X4[@]}"; fi
  if has long; then run m1_paper_strain2 dem_stokes paper 1 paper_dem_stokes.toml 2 "$rep"; fi
  if has mn3; then run m1_paper_mn1e-3 dem_stokes paper 1 paper_dem_stokes.toml 0.25 "$rep" "${MN3SET[@]}"; fi
done
load1=$(cut -d' ' -f1-3 /proc/loadavg)
finished=$(date -u '+%Y-%m-%d %H:%M UTC')

autogroup="sched_autogroup_enabled=$(cat /proc/sys/kernel/sched_autogroup_enabled 2>/dev/null || echo n/a), this session's autogroup: $(cat /proc/self/autogroup 2>/dev/null || echo n/a)"
python3 - "$RUNS" "$MRF" "$started" "$finished" "$load0" "$load1" "$autogroup" "${ARGS[*]}" <<'PYEOF'
import json, math, os, subprocess, sys
from collections import OrderedDict

runs_file, mrf, started, finished, load0, load1, autogroup, args = sys.argv[1:9]
rows = []
for line in open(runs_file):
    label, model, cell, threads, rep, rss, cpu, path = line.rstrip("\n").split("\t")
    d = json.load(open(path))
    rows.append(dict(label=label, model=model, cell=cell, threads=int(threads), rep=int(rep),
                     rss_kb=float(rss), cpu=cpu, **{k: d.get(k) for k in (
                         "n_particles", "n_wall", "n_fluid", "steps", "wall_seconds", "strain",
                         "seconds_per_strain", "mason", "integrator", "neighbor_builds",
                         "implicit_newton_iterations", "implicit_linear_iterations",
                         "implicit_rejected_steps", "stress_total", "git_revision")}))

def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True).stdout.strip()
    except Exception:
        return "?"

def mean(v): return sum(v) / len(v)

def fmt(vals, f): return ", ".join(f.format(v) for v in vals)

def linfit(x, y):
    n = len(x); mx = mean(x); my = mean(y)
    sxx = sum((a - mx) ** 2 for a in x); sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    b = sxy / sxx; a = my - b * mx
    se = math.sqrt(sum((yy - a - b * xx) ** 2 for xx, yy in zip(x, y)) / (n - 2) / sxx) if n > 2 else float("nan")
    return a, b, se

model_name = sh("lscpu | sed -n 's/^Model name: *//p' | head -1")
print("# Single-run scaling (generated by benchmarks/scaling.sh)")
print()
print(f"- command: `benchmarks/scaling.sh {args}`")
print(f"- date: {started} to {finished}")
print(f"- machine: nproc = {sh('nproc')}, lscpu model '{model_name}'; load average (1, 5, 15 min) "
      f"{load0} at start, {load1} at end; {autogroup}")
print(f"- binary: `{os.path.basename(mrf)} --version`: {sh(mrf + ' --version')}")
print("- every run: warm-up 0 from the scene's random start, `numerics.threads` = OMP_NUM_THREADS = threads; "
      "times are summary.json `wall_seconds` (the time-step loop), RSS the process's max RSS")
print()

groups = OrderedDict()
for r in rows:
    groups.setdefault(r["label"], []).append(r)

print("| run | model | cell | N free | N wall | N fluid | threads | Mn | strain | steps | wall s | ms / step "
      "| us / particle-step | s / strain | Newton / step | CG / Newton | Verlet builds / step | max RSS MB |")
print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for label, rs in groups.items():
    r0 = rs[0]
    ms = [1e3 * r["wall_seconds"] / r["steps"] for r in rs]
    ups = [1e6 * r["wall_seconds"] / (r["steps"] * r["n_particles"]) for r in rs]
    nw = r0["implicit_newton_iterations"]; cg = r0["implicit_linear_iterations"]
    newton = f"{nw / r0['steps']:.2f}" if nw else "-"
    cgn = f"{cg / nw:.2f}" if nw else "-"
    print(f"| {label} | {r0['model']} | {r0['cell']} | {r0['n_particles']} | {r0['n_wall']} | {r0['n_fluid']} | "
          f"{r0['threads']} | {r0['mason']:g} | {r0['strain']:g} | {fmt([r['steps'] for r in rs], '{}')} | "
          f"{fmt([r['wall_seconds'] for r in rs], '{:.2f}')} | {fmt(ms, '{:.2f}')} | {fmt(ups, '{:.2f}')} | "
          f"{fmt([r['seconds_per_strain'] for r in rs], '{:.2f}')} | {newton} | {cgn} | "
          f"{r0['neighbor_builds'] / r0['steps']:.2f} | {fmt([r['rss_kb'] / 1024 for r in rs], '{:.1f}')} |")
print()
print("Reps in order, comma separated. Newton / step, CG / Newton and Verlet builds / step from the first rep "
      "(`implicit_newton_iterations` / steps, `implicit_linear_iterations` / `implicit_newton_iterations`, "
      "`neighbor_builds` / steps). Integrator: "
      + ", ".join(sorted({f"{r['model']}: {r['integrator']}" for r in rows})) + ".")
det = []
for label, rs in groups.items():
    if len(rs) > 1:
        same = all(r["stress_total"] == rs[0]["stress_total"] and r["steps"] == rs[0]["steps"] for r in rs)
        det.append(f"{label} {'identical' if same else 'DIFFERENT'}")
if det:
    print("Repeated runs, stress_total and steps bit for bit: " + "; ".join(det) + ".")
print()

# the paper-cell family: 1 thread, Mn 1e-2, the standard strain of the model
def family(model, strain):
    return [g for l, g in groups.items() if g[0]["model"] == model and g[0]["cell"].startswith("paper")
            and g[0]["threads"] == 1 and g[0]["mason"] == 0.01 and g[0]["strain"] == strain
            and "_t" not in l and "ckpt" not in l]

fits = []
for model, strain in (("dem_stokes", 0.5), ("demsph_dd", 0.25)):
    fam = family(model, strain)
    if len(fam) < 2:
        continue
    ns = [g[0]["n_particles"] for g in fam]
    x = [math.log(n) for n in ns]
    for what, val in (("time per step", lambda r: r["wall_seconds"] / r["steps"]),
                      ("seconds per strain", lambda r: r["seconds_per_strain"])):
        y = [math.log(mean([val(r) for r in g])) for g in fam]
        a, b, se = linfit(x, y)
        fits.append(f"- {model}, {what} ~ N^b over N = {', '.join(map(str, ns))}: b = {b:.3f} +- {se:.3f}")
    y = [mean([r["rss_kb"] for r in g]) / 1024 for g in fam]
    a, b, se = linfit(ns, y)
    res = ", ".join(f"{yy - a - b * n:+.1f}" for n, yy in zip(ns, y))
    fits.append(f"- {model}, max RSS = a + b N over N = {', '.join(map(str, ns))}: a = {a:.1f} MB, "
                f"b = {1024 * 1024 * b:.0f} +- {1024 * 1024 * se:.0f} bytes per free sphere (residuals {res} MB)")
if fits:
    print("## Fits (paper-cell family, 1 thread, mean of the reps; +- is the standard error)")
    print()
    print("\n".join(fits))
    print()

pairs = [(l, g, groups[l[:-1] + "2"]) for l, g in groups.items() if l.endswith("_t1") and (l[:-1] + "2") in groups]
if pairs:
    print("## Threads (1 against 2, the same scene, run side by side)")
    print()
    print("| cell | model | wall s, 1 thread | wall s, 2 threads | speed-up per rep | efficiency | CPU of the 2-thread runs (/usr/bin/time) |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for l, g, g2 in pairs:
        t1 = [r["wall_seconds"] for r in g]; t2 = [r["wall_seconds"] for r in g2]
        sp = [a / b for a, b in zip(t1, t2)]
        print(f"| {g[0]['cell']} | {g[0]['model']} | {fmt(t1, '{:.2f}')} | {fmt(t2, '{:.2f}')} | "
              f"{fmt(sp, '{:.2f}')} | {fmt([s / 2 for s in sp], '{:.0%}')} | {', '.join(r['cpu'] for r in g2)} |")
PYEOF
