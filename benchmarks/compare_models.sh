#!/usr/bin/env bash
# Issue 5: the three models side by side on one base scene, in one script run.
#
#   benchmarks/compare_models.sh [SCENE] [MASON...]
#
# SCENE defaults to experiments/scenes/small_dem_stokes.toml; every model runs
# from that same file through --set scene.model=... (the coupled models read
# [fluid] sph_spacing from it; dem_stokes ignores it), so box, particles,
# seed and drive are identical. STRAIN / WARMUP (defaults 6 / 2) set the run
# length. Prints stress parts with block-average errors and the wall time per
# strain unit, and the cost ratio coupled / DEM, into
# reports/performance/compare_models_<scene>.md. For the paper scene:
#   STRAIN=1 WARMUP=0 benchmarks/compare_models.sh experiments/scenes/paper_dem_stokes.toml 1e-2 One OpenMP thread per run; runs go
# one after the other so they do not compete for the 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
MRF=$BUILD/mrf
SCENE=${1:-experiments/scenes/small_dem_stokes.toml}
shift || true
MASONS=${*:-1e-2 1e-1}
STRAIN=${STRAIN:-6}
WARMUP=${WARMUP:-2}
OUT=reports/performance
TMP=${TMPDIR:-/tmp}/mrf-compare
PY=${PY:-python3}
mkdir -p "$OUT" "$TMP"
rows=()
for mn in $MASONS; do
  for model in dem_stokes demsph_stokes demsph_dd; do
    dir=$TMP/$(basename "$SCENE" .toml)-$model-$mn
    OMP_NUM_THREADS=1 "$MRF" run "$SCENE" --quiet --set scene.model=\"$model\" --set drive.mason=$mn \
      --set drive.strain=$STRAIN --set drive.warmup_strain=$WARMUP --out "$dir" >/dev/null
    rows+=("$dir/summary.json")
  done
done
name=$(basename "$SCENE" .toml)
"$PY" - "${rows[@]}" <<'PYEOF' | tee "$OUT/compare_models_$name.md"
import json, sys
runs = [json.load(open(f)) for f in sys.argv[1:]]
print("| model | Mn | stress_total (Pa) | particles (Pa) | fluid (Pa) | pair virial (Pa) | virial total (Pa) | dt (s) | s/strain | cost / dem_stokes |")
print("|---|---|---|---|---|---|---|---|---|---|")
base = {}
for r in runs:
    sps = r["wall_seconds"] / r["strain"]
    if r["model"] == "dem_stokes": base[r["mason"]] = sps
    ratio = sps / base[r["mason"]]
    print(f"| {r['model']} | {r['mason']:g} | {r['stress_total']:.0f} +- {r['stress_total_err']:.0f} | "
          f"{r['stress_particles']:.0f} | {r['stress_fluid']:.0f} | {r['stress_virial']:.0f} +- {r['stress_virial_err']:.0f} | "
          f"{r['stress_virial_total']:.0f} +- {r['stress_virial_total_err']:.0f} | "
          f"{r['dt']:.3g} | {sps:.2f} | {ratio:.2f} |")
PYEOF
