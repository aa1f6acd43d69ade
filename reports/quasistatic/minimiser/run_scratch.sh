#!/bin/bash
# Minimiser comparison for issue 17 (reports/quasistatic/minimiser.md).
cd "$(dirname "$0")/../../.."
B=${MRF:-build/mrf}
S=experiments/scenes/small_dem_stokes.toml
P=experiments/scenes/paper_dem_stokes.toml
run() { local name=$1; shift; echo "=== $name $(date +%T)"; /usr/bin/time -f "$name wall %e s" $B quasistatic "$@" --quiet --out out/minimiser/$name --set numerics.threads=1 2>&1 | tail -2; }
for m in fire lbfgs; do
  for t in 1e-5 1e-6; do
    run small_y2_${m}_tol$t $S --set contact.youngs_modulus='2 GPa' --increment 1e-2 --tol $t --strain 0.2 --warmup 0.02 --minimiser $m
  done
done
for mem in 3 30; do
  run small_y2_lbfgs_m${mem}_tol1e-6 $S --set contact.youngs_modulus='2 GPa' --increment 1e-2 --tol 1e-6 --strain 0.2 --warmup 0.02 --minimiser lbfgs --lbfgs-memory $mem
done
for m in fire lbfgs; do
  run small_y200_${m}_tol1e-5 $S --increment 1e-2 --tol 1e-5 --strain 0.1 --warmup 0.02 --minimiser $m
done
for m in lbfgs fire; do
  run paper_y2_${m}_tol1e-5 $P --set contact.youngs_modulus='2 GPa' --increment 1e-2 --tol 1e-5 --strain 0.03 --warmup 0.0 --minimiser $m
done
echo "=== done $(date +%T)"
