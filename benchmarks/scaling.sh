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
  --mrf PATH   mrf binary (default: $MRF, else build/mrf)
  --reps N     repetitions of every timing (default 2; each is reported)
  --work DIR   scratch output directories (default ${TMPDIR:-/tmp}/mrf-scaling)
  --quick      only the small and paper cells (about 1 minute)
  --no-mn3     skip the model-1 runs at Mn = 1e-3
  -h, --help   this text

What runs (scenes from experiments/scenes/, their own Mn = 1e-2 at fixed
magnetisation 1 MA/m, Y = 200 GPa, so `auto` picks the implicit inertialess
scheme; warm-up 0, strain 0.5 for model 1 and 0.25 for model 3 from the
random start):
  model 1 (dem_stokes), 1 thread: small cell (375 spheres), paper cell
    (4125), paper cell 2x (ly 100 um), 4x (ly 100, lz 240 um), 8x (ly 200,
    lz 240 um); the paper cell to strain 2 (chains formed); the paper cell at
    Mn = 1e-3 (strain 0.25)
  model 3 (demsph_dd), 1 thread: small, paper, paper 2x, paper 4x
  threads: paper cell (models 1 and 3) and paper 4x (model 1) at 1 and 2
    threads, the 1- and 2-thread runs alternated
Each run's summary.json gives wall_seconds (time-step loop only), steps,
N and the implicit iteration counts; peak RSS is the process's max RSS.
Fits: log(time per step) = a + b log(N) over the model-1 paper-cell
family; RSS = a + b N per model (least squares on the mean of the reps).
EOF
}

MRF=${MRF:-build/mrf}
REPS=2
WORK=${TMPDIR:-/tmp}/mrf-scaling
QUICK=0
MN3=1
while [ $# -gt 0 ]; do
  case "$1" in
    --mrf) MRF=$2; shift 2 ;;
    --reps) REPS=$2; shift 2 ;;
    --work) WORK=$2; shift 2 ;;
    --quick) QUICK=1; shift ;;
    --no-mn3) MN3=0; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "scaling.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
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
  local cmd=("$MRF" run "$SC/$scene" --quiet --out "$dir" --set drive.strain="$strain"
             --set drive.warmup_strain=0 --set numerics.threads="$threads" "$@")
  if [ -x /usr/bin/time ]; then
    OMP_NUM_THREADS=$threads /usr/bin/time -v -o "$tfile" "${cmd[@]}" >/dev/null
    rss=$(awk -F: '/Maximum resident set size/{gsub(/ /,"",$2); print $2}' "$tfile")
  else
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
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$label" "$model" "$cell" "$threads" "$rep" "$rss" "$dir/summary.json" >>"$RUNS"
  echo "  done $label rep $rep (max RSS ${rss} kB)" >&2
}

X2=(--set 'box.ly="100 um"')
X4=(--set 'box.ly="100 um"' --set 'box.lz="240 um"')
X8=(--set 'box.ly="200 um"' --set 'box.lz="240 um"')
MN3SET=(--set drive.mason=1e-3)

started=$(date -u '+%Y-%m-%d %H:%M UTC')
load0=$(cut -d' ' -f1-3 /proc/loadavg)
for rep in $(seq "$REPS"); do
  echo "repetition $rep of $REPS" >&2
  run m1_small  dem_stokes small 1 small_dem_stokes.toml 0.5 "$rep"
  run m1_paper  dem_stokes paper 1 paper_dem_stokes.toml 0.5 "$rep"
  run m3_small  demsph_dd  small 1 small_demsph_dd.toml 0.5 "$rep"
  run m3_paper  demsph_dd  paper 1 paper_demsph_dd.toml 0.25 "$rep"
  # threads: 1 and 2 side by side, the order alternated between repetitions
  for t in $( [ $((rep % 2)) -eq 1 ] && echo "2 1" || echo "1 2"); do
    run m1_paper_t$t dem_stokes paper "$t" paper_dem_stokes.toml 0.5 "$rep"
    run m3_paper_t$t demsph_dd  paper "$t" paper_demsph_dd.toml 0.25 "$rep"
  done
  [ "$QUICK" = 1 ] && continue
  run m1_paper2x dem_stokes paper2x 1 paper_dem_stokes.toml 0.5 "$rep" "${X2[@]}"
  run m1_paper4x dem_stokes paper4x 1 paper_dem_stokes.toml 0.5 "$rep" "${X4[@]}"
  run m1_paper8x dem_stokes paper8x 1 paper_dem_stokes.toml 0.5 "$rep" "${X8[@]}"
  run m3_paper2x demsph_dd  paper2x 1 paper_demsph_dd.toml 0.25 "$rep" "${X2[@]}"
  run m3_paper4x demsph_dd  paper4x 1 paper_demsph_dd.toml 0.25 "$rep" "${X4[@]}"
  for t in $( [ $((rep % 2)) -eq 1 ] && echo "1 2" || echo "2 1"); do
    run m1_paper4x_t$t dem_stokes paper4x "$t" paper_dem_stokes.toml 0.5 "$rep" "${X4[@]}"
  done
  run m1_paper_strain2 dem_stokes paper 1 paper_dem_stokes.toml 2 "$rep"
  [ "$MN3" = 1 ] && run m1_paper_mn1e-3 dem_stokes paper 1 paper_dem_stokes.toml 0.25 "$rep" "${MN3SET[@]}"
done
load1=$(cut -d' ' -f1-3 /proc/loadavg)
finished=$(date -u '+%Y-%m-%d %H:%M UTC')

python3 - "$RUNS" "$MRF" "$started" "$finished" "$load0" "$load1" <<'PYEOF'
import json, math, os, subprocess, sys
from collections import defaultdict, OrderedDict

runs_file, mrf, started, finished, load0, load1 = sys.argv[1:7]
rows = []
for line in open(runs_file):
    label, model, cell, threads, rep, rss, path = line.rstrip("\n").split("\t")
    d = json.load(open(path))
    rows.append(dict(label=label, model=model, cell=cell, threads=int(threads), rep=int(rep),
                     rss_kb=float(rss), **{k: d.get(k) for k in (
                         "n_particles", "n_wall", "n_fluid", "steps", "wall_seconds", "strain",
                         "seconds_per_strain", "mason", "integrator", "neighbor_builds",
                         "implicit_newton_iterations", "implicit_linear_iterations",
                         "implicit_rejected_steps", "stress_total", "git_revision")}))

def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True).stdout.strip()
    except Exception:
        return "?"

model_name = sh("lscpu | sed -n 's/^Model name: *//p' | head -1")
print("# Single-run scaling (generated by benchmarks/scaling.sh)")
print()
print(f"- date: {started} to {finished}")
print(f"- machine: nproc = {sh('nproc')}, lscpu model '{model_name}', "
      f"load average (1, 5, 15 min) {load0} at start, {load1} at end")
print(f"- binary: `{os.path.basename(mrf)} --version`: {sh(mrf + ' --version')}")
print("- every run: warm-up 0 from the scene's random start, `numerics.threads` = OMP_NUM_THREADS = threads; "
      "times are summary.json `wall_seconds` (the time-step loop), RSS is the process's max RSS")
print()

groups = OrderedDict()
for r in rows:
    groups.setdefault(r["label"], []).append(r)

def fmt(vals, f):
    return ", ".join(f.format(v) for v in vals)

print("| run | model | cell | N free | N wall | N fluid | threads | Mn | strain | steps | wall s | ms / step | us / particle-step | s / strain | Newton / step | CG / Newton | max RSS MB |")
print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for label, rs in groups.items():
    r0 = rs[0]
    ms = [1e3 * r["wall_seconds"] / r["steps"] for r in rs]
    ups = [1e6 * r["wall_seconds"] / (r["steps"] * r["n_particles"]) for r in rs]
    nw = r0["implicit_newton_iterations"]; cg = r0["implicit_linear_iterations"]
    newton = f"{nw / r0['steps']:.2f}" if nw else "-"
    cgn = f"{cg / nw:.2f}" if nw else "-"
    steps = fmt([r["steps"] for r in rs], "{}")
    print(f"| {label} | {r0['model']} | {r0['cell']} | {r0['n_particles']} | {r0['n_wall']} | {r0['n_fluid']} | "
          f"{r0['threads']} | {r0['mason']:g} | {r0['strain']:g} | {steps} | {fmt([r['wall_seconds'] for r in rs], '{:.2f}')} | "
          f"{fmt(ms, '{:.2f}')} | {fmt(ups, '{:.2f}')} | {fmt([r['seconds_per_strain'] for r in rs], '{:.2f}')} | "
          f"{newton} | {cgn} | {fmt([r['rss_kb'] / 1024 for r in rs], '{:.1f}')} |")
print()
print("Reps are listed in order, comma separated. Newton / step and CG / Newton are from the first rep "
      "(`implicit_newton_iterations` / steps, `implicit_linear_iterations` / `implicit_newton_iterations`). "
      "Integrator: " + ", ".join(sorted({f"{r['model']}: {r['integrator']}" for r in rows})) + ".")
det = []
for label, rs in groups.items():
    if len(rs) > 1:
        same = all(r["stress_total"] == rs[0]["stress_total"] and r["steps"] == rs[0]["steps"] for r in rs)
        det.append(f"{label} {'identical' if same else 'DIFFERENT'}")
print("Repeated runs, stress_total and steps bit for bit: " + "; ".join(det) + ".")
print()

def mean(v): return sum(v) / len(v)

def linfit(x, y):
    n = len(x); mx = mean(x); my = mean(y)
    sxx = sum((a - mx) ** 2 for a in x); sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    b = sxy / sxx; a = my - b * mx
    se = math.sqrt(sum((yy - a - b * xx) ** 2 for xx, yy in zip(x, y)) / (n - 2) / sxx) if n > 2 else float("nan")
    return a, b, se

print("## Fits")
print()
fam = [g for l, g in groups.items() if l.startswith("m1_paper") and g[0]["threads"] == 1
       and g[0]["strain"] == 0.5 and g[0]["mason"] == 0.01 and "_t" not in l]
if len(fam) >= 2:
    x = [math.log(g[0]["n_particles"]) for g in fam]
    y = [math.log(mean([r["wall_seconds"] / r["steps"] for r in g])) for g in fam]
    a, b, se = linfit(x, y)
    ns = ", ".join(str(g[0]["n_particles"]) for g in fam)
    print(f"- model 1, time per step ~ N^b over the paper-cell family (N = {ns}, 1 thread, mean of reps): "
          f"b = {b:.3f} +- {se:.3f}")
for model in ("dem_stokes", "demsph_dd"):
    gs = [g for l, g in groups.items() if g[0]["model"] == model and g[0]["threads"] == 1 and "_t" not in l
          and g[0]["mason"] == 0.01 and g[0]["strain"] <= 0.5]
    if len(gs) >= 2:
        x = [g[0]["n_particles"] for g in gs]
        y = [mean([r["rss_kb"] for r in g]) / 1024 for g in gs]
        a, b, se = linfit(x, y)
        extra = ""
        nf = [g[0]["n_fluid"] for g in gs]
        if any(nf):
            extra = f" (fluid particles per free sphere: {', '.join(f'{f / n:.3f}' for f, n in zip(nf, x))})"
        print(f"- {model}, max RSS = a + b N over N = {', '.join(map(str, x))}: a = {a:.1f} MB, "
              f"b = {1024 * 1024 * b:.0f} +- {1024 * 1024 * se:.0f} bytes per free sphere{extra}")
print()
print("## Threads (1 against 2, the same scene, run side by side)")
print()
print("| cell | model | wall s, 1 thread | wall s, 2 threads | speed-up per rep | efficiency |")
print("|---|---|---:|---:|---:|---:|")
for l, g in groups.items():
    if l.endswith("_t1"):
        g2 = groups.get(l[:-1] + "2")
        if not g2: continue
        t1 = [r["wall_seconds"] for r in g]; t2 = [r["wall_seconds"] for r in g2]
        sp = [a / b for a, b in zip(t1, t2)]
        print(f"| {g[0]['cell']} | {g[0]['model']} | {fmt(t1, '{:.2f}')} | {fmt(t2, '{:.2f}')} | "
              f"{fmt(sp, '{:.2f}')} | {fmt([s / 2 for s in sp], '{:.0%}')} |")
PYEOF
