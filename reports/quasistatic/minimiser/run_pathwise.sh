#!/bin/bash
# Pathwise: from the same FIRE minimum, FIRE goes on (resume) and L-BFGS goes on (branch).
cd "$(dirname "$0")/../../.."
B=${MRF:-build/mrf}
S=experiments/scenes/small_dem_stokes.toml
P=experiments/scenes/paper_dem_stokes.toml
pair() { # base scene strain sets...
  local base=$1 scene=$2 strain=$3; shift 3
  rm -rf out/minimiser/${base}_fire_on out/minimiser/${base}_lbfgs_branch
  cp -r out/minimiser/$base out/minimiser/${base}_fire_on
  echo "=== ${base}_fire_on $(date +%T)"
  /usr/bin/time -f "${base}_fire_on wall %e s" $B quasistatic $scene "$@" --minimiser fire --strain $strain --resume --quiet --out out/minimiser/${base}_fire_on 2>&1 | tail -2
  echo "=== ${base}_lbfgs_branch $(date +%T)"
  /usr/bin/time -f "${base}_lbfgs_branch wall %e s" $B quasistatic $scene "$@" --minimiser lbfgs --strain $strain --branch-from out/minimiser/$base/checkpoint.bin --quiet --out out/minimiser/${base}_lbfgs_branch 2>&1 | tail -2
}
pair small_y2_fire_tol1e-6 $S 0.6 --set numerics.threads=1 --set contact.youngs_modulus='2 GPa' --increment 1e-2 --tol 1e-6 --warmup 0.02
pair small_y200_fire_tol1e-5 $S 0.3 --set numerics.threads=1 --increment 1e-2 --tol 1e-5 --warmup 0.02
pair paper_y2_fire_tol1e-5 $P 0.06 --set numerics.threads=1 --set contact.youngs_modulus='2 GPa' --increment 1e-2 --tol 1e-5 --warmup 0.0
echo "=== done $(date +%T)"
