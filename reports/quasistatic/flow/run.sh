#!/bin/bash
# Dynamic model 1 on the small cell at Y = 2 GPa from Mn 1e-2 down to 1e-6,
# and AQS (FIRE, L-BFGS) from the last frame of each run and from the packing
# (reports/quasistatic/flow_vs_aqs.md). Resumable: finished runs are skipped.
# MRF=path/to/mrf (default build/mrf); OUT (default out/flowprep).
cd "$(dirname "$0")/../../.."
B=${MRF:-build/mrf}; S=experiments/scenes/small_dem_stokes.toml; D=${OUT:-out/flowprep}
Y='contact.youngs_modulus="2 GPa"'
mkdir -p $D
dynamic() { # mn seed strain warmup
  local r=$D/run_mn$1_s$2
  [ -f $r/summary.json ] || $B run $S --set "$Y" --set drive.mason=$1 --set scene.seed=$2 --set drive.strain=$3 \
    --set drive.warmup_strain=$4 --set output.frames=10 --set numerics.threads=1 --out $r --checkpoint-every 120 --resume --quiet
}
aqs() { # name seed minimiser [--start-from FRAMES]
  local q=$D/aqs_$1_$3 name=$1 seed=$2 m=$3; shift 3
  [ -f $q/summary.json ] || $B quasistatic $S --set "$Y" --set scene.seed=$seed --set numerics.threads=1 --increment 1e-2 \
    --tol 1e-6 --strain 0.4 --warmup 0.0 --minimiser $m --quiet --out $q "$@"
}
for seed in 1 2 3; do
  dynamic 1e-2 $seed 6 2
  dynamic 1e-3 $seed 3 1
  dynamic 1e-4 $seed 3 1
  dynamic 1e-5 $seed 3 1
  for mn in 1e-2 1e-3; do for m in fire lbfgs; do aqs mn${mn}_s$seed $seed $m --start-from $D/run_mn${mn}_s$seed/frames.xyz; done; done
  for mn in 1e-4 1e-5; do aqs mn${mn}_s$seed $seed fire --start-from $D/run_mn${mn}_s$seed/frames.xyz; done
  for m in fire lbfgs; do aqs packing_s$seed $seed $m; done
done
dynamic 1e-6 1 3 1
# The flowing state at Mn 1e-4 (seed 1) relaxed by each minimiser to tol 1e-4 F0 (the first minimum only).
for m in fire lbfgs descent; do
  q=$D/relax_mn1e-4_s1_$m
  [ -f $q/summary.json ] || $B quasistatic $S --set "$Y" --set scene.seed=1 --set numerics.threads=1 --increment 1e-2 \
    --tol 1e-4 --strain 0.01 --warmup 0 --minimiser $m --max-iterations 20000000 \
    --start-from $D/run_mn1e-4_s1/frames.xyz --quiet --out $q
done
