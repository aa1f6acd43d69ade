#!/usr/bin/env bash
# mrf against LAMMPS on the identical DEM-Stokes shear cell (issue 3), both
# codes run one after the other in this script, serial (one thread, one MPI
# rank), so that the ratios are measured side by side on the same machine.
#
#   benchmarks/peers/lammps/compare.sh [--mason 1e-2] [--steps 2000] [--reps 2]
#        [--strain 0.25] [--window 0.05] [--scene FILE] [--work DIR] [--no-results]
#        [--set KEY=VALUE]... [--dt-a DT]
#
#   --set overrides a key of the scene for the export and every mrf run (the
#   soft-contact variant: --set contact.youngs_modulus='"0.1 GPa"'
#   --set particles.magnetization=3e5 --set dipole_cutoff=... as in issue 16);
#   --dt-a runs (a) at that dt instead of mrf's automatic one (LAMMPS's 1e-8 s).
#
#   0. force-law check of the LAMMPS mapping (in.check_forces) and a start-up
#      check: dipole energy and virial stress of both codes over the first
#      steps from the same initial configuration;
#   (a) throughput: --steps steps at the SAME dt (mrf's automatic dt), --reps
#       times alternating the order; particle-steps/s = free spheres x steps /
#       loop wall time;
#   (b) time to one strain unit, each code at its own largest stable dt (mrf:
#       automatic; LAMMPS: min(0.2 tau_p, the contact limit of its
#       velocity-Verlet + explicit-drag scheme at mrf's expected overlap,
#       times mrf's safety factor)); both run --strain strain units, --reps
#       times alternating the order, and the wall time is extrapolated
#       linearly to one strain unit; a stability probe runs strain 0.05 with
#       LAMMPS at 2x and 4x its dt and mrf at its limit (dt_safety = 1);
#   (c) the wall stress from particles of the first runs of (b), averaged
#       over the strain window [--window, --strain], also per block.
# Prints a table and writes benchmarks/peers/lammps/results.md.
#
# Environment: MRF_BUILD_DIR (default ROOT/build; built with cmake if the
# mrf binary is missing or out of date), LMP (default lmp).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
build="${MRF_BUILD_DIR:-$root/build}"
lmp="${LMP:-lmp}"
mason=1e-2
steps=2000
reps=2
strain=0.25
window=0.05
scene="$root/experiments/scenes/paper_dem_stokes.toml"
work=""
write_results=1
sets=()
dt_a=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --mason) mason="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --reps) reps="$2"; shift 2 ;;
    --strain) strain="$2"; shift 2 ;;
    --window) window="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --no-results) write_results=0; shift ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    --dt-a) dt_a="$2"; shift 2 ;;
    -h|--help) sed -n '2,33p' "$0"; exit 0 ;;
    *) echo "compare.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
(( steps >= 40 )) || { echo "compare.sh: --steps must be >= 40 (mrf needs 32 time-series rows to average)" >&2; exit 2; }
[[ -n "$work" ]] || work="$(mktemp -d /tmp/mrf_lammps_compare.XXXXXX)"
mkdir -p "$work"
cmds="$work/commands.txt"
: > "$cmds"
export OMP_NUM_THREADS=1

log_cmd() { printf '%s\n' "$*" >> "$cmds"; }
run() { log_cmd "$*"; "$@"; }

command -v "$lmp" >/dev/null || { echo "compare.sh: LAMMPS binary '$lmp' not found (apt-get install lammps)" >&2; exit 1; }

# --- build mrf (incremental) --------------------------------------------------
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  run cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release > "$work/cmake.log"
fi
run cmake --build "$build" -j2 --target mrf_cli > "$work/build.log" 2>&1 || {
  echo "compare.sh: building mrf failed, see $work/build.log" >&2; exit 1; }
mrf="$build/mrf"

# --- scene export ---------------------------------------------------------------
prefix="$work/scene"
# mrf's explicit scheme is the one compared step for step (its dt is the one
# LAMMPS is given in (a)); the implicit scheme enters (b) as a second mrf entry.
run "$mrf" export-lammps "$scene" --set "drive.mason=$mason" --set numerics.integrator=verlet_exp "${sets[@]}" --out "$prefix" > "$work/export.log"
pget() { awk -v k="$1" '$1=="variable" && $2==k {print $4}' "$prefix.params"; }
dt_mrf="$(pget dt_mrf)"
gdot="$(pget shear_rate)"
tau_p="$(pget tau_p)"
echo "compare.sh: work directory $work"
echo "  scene $(basename "$scene"), Mn = $mason, shear rate $gdot 1/s, dt_mrf $dt_mrf s, tau_p $tau_p s"

calc() { python3 -c "import math; print(repr($1))"; }
# mrf runs N steps when drive.strain = (N - 1/2) gdot dt (it takes ceil(strain/(gdot dt))).
strain_for_steps() { calc "($1 - 0.5) * $gdot * $2"; }

mrf_run() {  # name strain warmup [extra --set ...]; integrator $mrf_int (default verlet_exp)
  local name="$1" s="$2" w="$3"; shift 3
  run "$mrf" run "$scene" --set "drive.mason=$mason" --set "drive.strain=$s" \
      --set "drive.warmup_strain=$w" --set "numerics.integrator=${mrf_int:-verlet_exp}" "${sets[@]}" "$@" \
      --out "$work/$name" > "$work/$name.stdout" 2> "$work/$name.stderr"
}
lmp_run() {  # name nsteps dt nave thermo_every
  run "$lmp" -in "$here/in.mrf_shear" -var dir "$here" -var prefix "$prefix" -var nsteps "$2" \
      -var dt "$3" -var nave "$4" -var thermo_every "$5" -var tag "$work/$1" \
      -log "$work/$1.log" -screen none
}

# --- 0. checks --------------------------------------------------------------------
echo "  [0] force-law check of the LAMMPS mapping"
log_cmd "$lmp -in $here/in.check_forces -var dir $here -var prefix $prefix -log $work/check_forces.log -screen none"
"$lmp" -in "$here/in.check_forces" -var dir "$here" -var prefix "$prefix" -log "$work/check_forces.log" -screen none
check_max="$(awk '$1=="CHECK_MAX_REL_ERR" {print $2}' "$work/check_forces.log" | tail -1)"
python3 -c "import sys; sys.exit(0 if float('$check_max') < 1e-9 else 1)" || {
  echo "compare.sh: LAMMPS force-law check failed (max rel. error $check_max), see $work/check_forces.log" >&2; exit 1; }
echo "      max relative error $check_max"

echo "  [0] start-up trajectory check (40 steps from the same configuration; at t = 10 dt also at dt/2, dt/4)"
mrf_run startup "$(strain_for_steps 40 "$dt_mrf")" 0 --set output.every=1
lmp_run startup_lmp 40 "$dt_mrf" 1 1
for q in 2 4; do
  dtq="$(calc "$dt_mrf / $q")"
  mrf_run "startup_q$q" "$(strain_for_steps 40 "$dtq")" 0 --set output.every=1 --set numerics.dt="$dtq"
  lmp_run "startup_lmp_q$q" $((10 * q)) "$dtq" $((10 * q)) $((10 * q))
done

# --- (a) throughput at equal dt ---------------------------------------------------------
dt_eq="${dt_a:-$dt_mrf}"
for ((r = 1; r <= reps; r++)); do
  if (( r % 2 == 1 )); then order="mrf lmp"; else order="lmp mrf"; fi
  for code in $order; do
    echo "  [a] rep $r: $code, $steps steps at dt = $dt_eq s"
    if [[ "$code" == mrf ]]; then
      mrf_run "a_mrf_$r" "$(strain_for_steps "$steps" "$dt_eq")" 0 --set numerics.dt="$dt_eq"
    else
      lmp_run "a_lmp_$r" "$steps" "$dt_eq" 100 "$steps"
    fi
  done
done

# --- LAMMPS' own largest stable dt ----------------------------------------------------
# mrf prints its limits at start-up (the start-up run: automatic dt); take its
# expected overlap and safety factor.
dt_basis="$(python3 - "$work/startup.stderr" "$prefix.params" <<'EOF'
import cmath, math, re, sys
text = open(sys.argv[1]).read()
par = {}
for line in open(sys.argv[2]):
    f = line.split()
    if len(f) >= 4 and f[0] == "variable":
        par[f[1]] = float(f[3])
m = re.search(r"verlet_exp\s+hertz contact\s+dt < (\S+)\s+expected overlap/R (\S+)", text)
limit_mrf, h_over_r = float(m.group(1)), float(m.group(2))
chosen = float(re.search(r"chosen: \S+, (?:fixed )?dt = (\S+) s", text).group(1))
safety = round(chosen / limit_mrf, 2)  # the limit is printed to 3 digits; mrf's dt_safety (0.5 by default)
R, mass, k, tau = par["radius"], par["mass"], par["hertz_k"], par["tau_p"]
h = h_over_r * R
k_eff = 1.5 * k * math.sqrt(h)
w2 = 2.0 * k_eff / mass  # free pair: reduced mass m/2

def step(x, v, a, dt):
    # LAMMPS velocity Verlet, drag from fix langevin on the half-step velocity
    vh = v + 0.5 * dt * a
    x1 = x + dt * vh
    a1 = -w2 * x1 - vh / tau
    return x1, vh + 0.5 * dt * a1, a1

def radius(dt):
    cols = [step(*e, dt) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    M = [[cols[j][i] for j in range(3)] for i in range(3)]
    tr = M[0][0] + M[1][1] + M[2][2]
    c1 = (M[0][0]*M[1][1] - M[0][1]*M[1][0] + M[0][0]*M[2][2] - M[0][2]*M[2][0]
          + M[1][1]*M[2][2] - M[1][2]*M[2][1])
    det = (M[0][0]*(M[1][1]*M[2][2]-M[1][2]*M[2][1]) - M[0][1]*(M[1][0]*M[2][2]-M[1][2]*M[2][0])
           + M[0][2]*(M[1][0]*M[2][1]-M[1][1]*M[2][0]))
    p = lambda z: z**3 - tr*z**2 + c1*z - det
    z = [complex(0.4, 0.9)**n for n in range(3)]  # Durand-Kerner
    for _ in range(500):
        z = [z[i] - p(z[i]) / ((z[i]-z[(i+1)%3]) * (z[i]-z[(i+2)%3])) for i in range(3)]
    return max(abs(x) for x in z)

lo = 1e-3 * min(1.0 / math.sqrt(w2), tau)
while radius(lo * 1.02) <= 1.0 + 1e-9:
    lo *= 1.02
hi = lo * 1.02
for _ in range(60):
    mid = 0.5 * (lo + hi)
    (lo, hi) = (mid, hi) if radius(mid) <= 1.0 + 1e-9 else (lo, mid)
contact = lo
drag = 0.2 * tau
dt = min(drag, safety * contact)
print(f"{dt!r} {contact!r} {drag!r} {safety!r} {h_over_r!r} {limit_mrf!r}")
EOF
)"
read -r dt_lmp dt_lmp_contact dt_lmp_drag safety h_over_r limit_mrf <<< "$dt_basis"
echo "  LAMMPS dt = $dt_lmp s = min(0.2 tau_p = $dt_lmp_drag, $safety x contact limit $dt_lmp_contact at overlap/R $h_over_r)"

# --- (b) + (c) time to strain and stress, each code at its own dt ---------------------------
# Stability probe over strain 0.05 from the start (where the fastest impacts
# happen): LAMMPS at 2x (= its analytic limit) and 4x its dt, mrf at its limit
# (numerics.dt_safety = 1; mrf refuses any dt above the limit).
echo "  [b] stability probe: LAMMPS at 2x and 4x its dt, mrf at dt_safety = 1 (strain 0.05)"
for f in 2 4; do
  dtp="$(calc "$dt_lmp * $f")"
  np="$(calc "int(math.ceil(0.05 / ($gdot * $dtp)))")"
  lmp_run "probe_lmp_x$f" "$np" "$dtp" 10 "$np" || true
done
mrf_run probe_mrf_limit 0.05 0 --set numerics.dt_safety=1 || true

nb_lmp="$(calc "int(math.ceil($strain / ($gdot * $dt_lmp)))")"
for ((r = 1; r <= reps; r++)); do
  if (( r % 2 == 1 )); then order="mrf lmp"; else order="lmp mrf"; fi
  for code in $order; do
    if [[ "$code" == mrf ]]; then
      echo "  [b] rep $r: mrf to strain $strain at its automatic dt (verlet_exp, then implicit)"
      mrf_run "b_mrf_$r" "$strain" "$window"
      # no warm-up for the implicit run: its rows come by strain interval (one per largest step),
      # and (c) takes the window from its time series anyway
      mrf_int=implicit mrf_run "b_mrf_implicit_$r" "$strain" 0
    else
      echo "  [b] rep $r: LAMMPS to strain $strain: $nb_lmp steps at dt = $dt_lmp s"
      lmp_run "b_lmp_$r" "$nb_lmp" "$dt_lmp" 10 "$nb_lmp"
    fi
  done
done

# --- analysis ---------------------------------------------------------------------------
python3 - "$work" "$reps" "$steps" "$strain" "$window" "$mason" "$scene" "$dt_basis" "$check_max" \
          "$write_results" "$here/results.md" "$lmp" <<'EOF'
import csv, json, math, os, platform, re, subprocess, sys, datetime
(work, reps, steps, strain, window, mason, scene, dt_basis, check_max, write_results,
 results_path, lmp) = sys.argv[1:]
reps, steps, strain, window = int(reps), int(steps), float(strain), float(window)
dt_lmp, dt_contact, dt_drag, safety, h_over_r, limit_mrf = map(float, dt_basis.split())
par = {l.split()[1]: float(l.split()[3]) for l in open(f"{work}/scene.params") if l.startswith("variable")}
gdot = par["shear_rate"]

def lmp_log(name):
    t = open(f"{work}/{name}.log").read()
    m = re.search(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms", t)
    cpu = re.search(r"([\d.]+)% CPU use", t)
    sec = {s: float(p) for s, p in re.findall(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|.*\|\s*([\d.]+)\s*$", t, re.M)}
    thermo = []
    blk = re.search(r"^\s*Step Time .*?\n(.*?)^Loop time", t, re.M | re.S)
    for line in blk.group(1).splitlines():
        f = line.split()
        if len(f) == 8 and f[0].isdigit():
            thermo.append([float(x) for x in f])
    nb = re.search(r"Neighbor list builds = (\d+)", t)
    return dict(loop=float(m.group(1)), steps=int(m.group(3)), atoms=int(m.group(4)),
                builds=int(nb.group(1)) if nb else -1,
                cpu=float(cpu.group(1)) if cpu else float("nan"), sections=sec, thermo=thermo)

def mrf_sum(name):
    return json.load(open(f"{work}/{name}/summary.json"))

n_free = mrf_sum("startup")["n_particles"]
out = []
P = out.append

# 0: start-up trajectory
ts = list(csv.DictReader(open(f"{work}/startup/timeseries.csv")))
lt = {int(r[0]): r for r in lmp_log("startup_lmp")["thermo"]}
P("Start-up check (same initial configuration, dt = %.4g s; LAMMPS thermo vs mrf time series):" % par["dt_mrf"])
P("")
P("| step | E_dip mrf (J) | E_dip LAMMPS (J) | rel. diff | sigma_virial mrf (Pa) | LAMMPS (Pa) | rel. diff |")
P("|---:|---:|---:|---:|---:|---:|---:|")
startup_worst = 0.0
for s in (1, 2, 5, 10, 20, 40):
    r = ts[s - 1]
    em = float(r["energy_dipole_J"]); vm = float(r["stress_virial_magnetic_Pa"]) + float(r["stress_virial_contact_Pa"])
    el = lt[s][5]; vl = lt[s][6]
    de, dv = abs(el - em) / abs(em), abs(vl - vm) / abs(vm)
    if s <= 10: startup_worst = max(startup_worst, de, dv)
    P(f"| {s} | {em:.8g} | {el:.8g} | {de:.1e} | {vm:.6g} | {vl:.6g} | {dv:.1e} |")
P("")
P("Convergence at t = 10 dt_mrf: both codes at dt/q from the same start (differences are time-discretisation error if they fall with dt):")
P("")
P("| q | E_dip mrf (J) | E_dip LAMMPS (J) | LAMMPS - mrf(q=4) (J) | sigma_virial mrf (Pa) | LAMMPS (Pa) |")
P("|---:|---:|---:|---:|---:|---:|")
conv = {}
for q in (1, 2, 4):
    tsq = list(csv.DictReader(open(f"{work}/startup{'' if q == 1 else f'_q{q}'}/timeseries.csv")))
    r = tsq[10 * q - 1]
    lq = {int(x[0]): x for x in lmp_log("startup_lmp" if q == 1 else f"startup_lmp_q{q}")["thermo"]}[10 * q]
    conv[q] = (float(r["energy_dipole_J"]), float(r["stress_virial_magnetic_Pa"]) + float(r["stress_virial_contact_Pa"]), lq[5], lq[6])
for q in (1, 2, 4):
    em, vm, el, vl = conv[q]
    P(f"| {q} | {em:.10g} | {el:.10g} | {el - conv[4][0]:.3g} | {vm:.6g} | {vl:.6g} |")
P("")

# (a) throughput
rows_a = []
for r in range(1, reps + 1):
    sm = mrf_sum(f"a_mrf_{r}"); ll = lmp_log(f"a_lmp_{r}")
    assert sm["steps"] == steps and ll["steps"] == steps, (sm["steps"], ll["steps"])
    assert sm["threads"] == 1, "mrf did not run on one thread"
    pm = n_free * steps / sm["wall_seconds"]; pl = n_free * steps / ll["loop"]
    rows_a.append((r, sm["wall_seconds"], ll["loop"], pm, pl, pm / pl, ll["cpu"], sm))
ratios_a = sorted(x[5] for x in rows_a)
median_a = ratios_a[len(ratios_a) // 2] if len(ratios_a) % 2 else 0.5 * (ratios_a[len(ratios_a)//2 - 1] + ratios_a[len(ratios_a)//2])
best_a = (n_free * steps / min(x[1] for x in rows_a)) / (n_free * steps / min(x[2] for x in rows_a))
pairs_per_step = rows_a[0][7]["pair_evaluations_per_second"] * rows_a[0][1] / steps

dt_eq = rows_a[0][7]["dt"]
P(f"(a) Throughput at equal dt = {dt_eq:.4g} s, {steps} steps, serial, {n_free} free spheres (particle-steps/s = {n_free} x steps / loop wall time):")
P("")
P("| rep | mrf loop (s) | LAMMPS loop (s) | mrf particle-steps/s | LAMMPS particle-steps/s | mrf/LAMMPS | LAMMPS %CPU | list builds per 1000 steps mrf / LAMMPS |")
P("|---:|---:|---:|---:|---:|---:|---:|---:|")
for r, tm, tl, pm, pl, q, cpu, sm in rows_a:
    bl = lmp_log(f"a_lmp_{r}")["builds"]
    P(f"| {r} | {tm:.2f} | {tl:.2f} | {pm:.4g} | {pl:.4g} | {q:.2f} | {cpu:.0f} | "
      f"{1000 * sm['neighbor_builds'] / steps:.1f} / {1000 * bl / steps:.1f} |")
P("")
P(f"Ratio mrf/LAMMPS per step: median {median_a:.2f}, best-of-{reps} times {best_a:.2f}. "
  f"Verlet-list entries per step (mrf, cut-off + skin): {pairs_per_step:.4g}; "
  f"list entries per loop second: mrf {pairs_per_step*steps/min(x[1] for x in rows_a):.3g}, "
  f"LAMMPS {pairs_per_step*steps/min(x[2] for x in rows_a):.3g} (same configuration, same cut-off and skin).")
sec = lmp_log(f"a_lmp_{reps}")["sections"]
tot = sum(sec.values())
P("LAMMPS time split (last rep): " + ", ".join(f"{k} {100*v/tot:.1f} %" for k, v in sec.items()) + ".")
P("")

# (b) time to one strain unit
def median(v):
    v = sorted(v); n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])

P(f"(b) Time to one strain unit at Mn = {float(mason):g} (shear rate {gdot:.5g} 1/s), each code at its own largest stable dt, "
  f"extrapolated linearly from measured runs to strain {strain:g} (--reps {reps}, order alternated):")
P("")
P("| rep | code | dt (s) | steps run | loop (s) | steps per strain | wall time per strain (s, extrapolated) |")
P("|---:|---|---:|---:|---:|---:|---:|")
ratios_b, ratios_bi = [], []
for r in range(1, reps + 1):
    bm = mrf_sum(f"b_mrf_{r}"); bl = lmp_log(f"b_lmp_{r}")
    assert bm["threads"] == 1, "mrf did not run on one thread"
    t1_mrf = bm["wall_seconds"] / (bm["steps"] * bm["dt"] * gdot)
    t1_lmp = bl["loop"] / (bl["steps"] * dt_lmp * gdot)
    ratios_b.append(t1_lmp / t1_mrf)
    P(f"| {r} | mrf ({bm['integrator']}) | {bm['dt']:.4g} | {bm['steps']} | {bm['wall_seconds']:.1f} | {1/(bm['dt']*gdot):.0f} | {t1_mrf:.0f} |")
    bi = mrf_sum(f"b_mrf_implicit_{r}")
    t1_imp = bi["wall_seconds"] / bi["strain"]
    ratios_bi.append(t1_lmp / t1_imp)
    P(f"| {r} | mrf (implicit, mean dt) | {bi['strain'] / (gdot * bi['steps']):.4g} | {bi['steps']} | {bi['wall_seconds']:.1f} | "
      f"{bi['steps'] / bi['strain']:.0f} | {t1_imp:.0f} |")
    P(f"| {r} | LAMMPS | {dt_lmp:.4g} | {bl['steps']} | {bl['loop']:.1f} | {1/(dt_lmp*gdot):.0f} | {t1_lmp:.0f} |")
bm = mrf_sum("b_mrf_1")
P("")
P(f"Basis of dt: mrf {bm['dt']:.4g} s = {safety:.2g} x its {bm['dt_bound_by']} limit {limit_mrf:.3g} s "
  f"(expected overlap/R {h_over_r:g}); LAMMPS {dt_lmp:.4g} s = min(0.2 tau_p = {dt_drag:.3g} s, {safety:.2g} x {dt_contact:.3g} s, "
  f"the stability limit of velocity Verlet with the explicit drag on the same contact at the same overlap).")
P(f"Ratio LAMMPS/mrf wall time per strain unit (>1: mrf faster): "
  + ", ".join(f"{x:.2f}" for x in ratios_b) + f"; median {median(ratios_b):.2f} (dt ratio mrf/LAMMPS {bm['dt']/dt_lmp:.2f}). "
  f"With mrf's implicit inertialess scheme: " + ", ".join(f"{x:.2f}" for x in ratios_bi)
  + f"; median {median(ratios_bi):.2f}.")
P("")

# stability probe
P("Stability probe, strain 0 - 0.05 from the random start (the fastest impacts):")
P("")
P("| code | dt (s) | outcome |")
P("|---|---:|---|")
for f in (2, 4):
    t = open(f"{work}/probe_lmp_x{f}.log").read()
    m = re.search(r"ERROR: (.*)", t)
    if m:
        outcome = "failed: " + m.group(1).strip()
    else:
        th = lmp_log(f"probe_lmp_x{f}")["thermo"][-1]
        outcome = f"completed {int(th[0])} steps, E_dip {th[5]:.5g} J, KE of free spheres {th[7]:.4g} J"
    P(f"| LAMMPS ({f} x its dt) | {f * dt_lmp:.4g} | {outcome} |")
if os.path.exists(f"{work}/probe_mrf_limit/summary.json"):
    pm = mrf_sum("probe_mrf_limit")
    tsp = list(csv.DictReader(open(f"{work}/probe_mrf_limit/timeseries.csv")))
    outcome = (f"completed {pm['steps']} steps, E_dip {float(tsp[-1]['energy_dipole_J']):.5g} J, "
               f"max overlap/R {pm['max_overlap_over_radius']:.3g}")
    P(f"| mrf (dt_safety = 1) | {pm['dt']:.4g} | {outcome} |")
else:
    err = open(f"{work}/probe_mrf_limit.stderr").read().strip().splitlines()
    P(f"| mrf (dt_safety = 1) | - | failed: {err[-1] if err else '?'} |")
P("")

# (c) stress cross-check
def window_stats(xs, ys, lo, hi, nblocks=8):
    pts = [(x, y) for x, y in zip(xs, ys) if lo <= x <= hi]
    if len(pts) < nblocks:
        return float("nan"), float("nan"), len(pts), []
    width = (hi - lo) / nblocks
    blocks = [[] for _ in range(nblocks)]
    for x, y in pts:
        blocks[min(nblocks - 1, int((x - lo) / width))].append(y)
    means = [sum(b) / len(b) for b in blocks if b]
    m = sum(means) / len(means)
    sem = math.sqrt(sum((v - m) ** 2 for v in means) / (len(means) - 1) / len(means))
    return m, sem, len(pts), means

tsb = list(csv.DictReader(open(f"{work}/b_mrf_1/timeseries.csv")))
xm = [float(r["strain"]) for r in tsb]; ym = [float(r["stress_particles_Pa"]) for r in tsb]
wl = [l.split() for l in open(f"{work}/b_lmp_1.wall.txt") if not l.startswith("#")]
# fix ave/time row at step N averages steps N-nave+1..N: centre strain (N - (nave-1)/2) dt gdot
xl = [(int(f[0]) - 4.5) * dt_lmp * gdot for f in wl]; yl = [float(f[1]) for f in wl]
sm_, em_, nm_, bm_ = window_stats(xm, ym, window, strain)
sl_, el_, nl_, bl_ = window_stats(xl, yl, window, strain)
# mrf's implicit inertialess run from the same start (St = 0.003: it should
# track the inertial runs while the chains form)
tsi = list(csv.DictReader(open(f"{work}/b_mrf_implicit_1/timeseries.csv")))
si_, ei_, ni_, bi_ = window_stats([float(r["strain"]) for r in tsi], [float(r["stress_particles_Pa"]) for r in tsi],
                                  window, strain)
diff = sl_ - sm_; comb = math.hypot(em_, el_)
P(f"(c) Wall shear stress from particles (runs of rep 1 of (b)), strain window [{window:g}, {strain:g}] (mean of 8 blocks +- standard error of the block means; "
  f"mrf's total adds the imposed-fluid part eta gdot = {bm['stress_fluid']:.5g} Pa):")
P("")
P("| code | tau_particles (Pa) | +- (Pa) | samples |")
P("|---|---:|---:|---:|")
P(f"| mrf | {sm_:.5g} | {em_:.2g} | {nm_} |")
P(f"| LAMMPS | {sl_:.5g} | {el_:.2g} | {nl_} |")
P(f"| mrf implicit (inertialess) | {si_:.5g} | {ei_:.2g} | {ni_} |")
P("")
P(f"Difference LAMMPS - mrf: {diff:.4g} Pa = {diff/comb if comb > 0 else float('nan'):.2f} combined standard errors "
  f"({100*diff/sm_ if sm_ else float('nan'):.2f} % of mrf). The block means (below) show how closely the two runs "
  f"track each other; where they rise through the window (the start-up transient: chains forming from the random start), the "
  f"standard error measures that rise, not noise.")
P("")
P("| strain block | mrf (Pa) | LAMMPS (Pa) | LAMMPS - mrf (Pa) | mrf implicit (Pa) |")
P("|---|---:|---:|---:|---:|")
w8 = (strain - window) / 8
for b, (a_, c_, i_) in enumerate(zip(bm_, bl_, bi_)):
    P(f"| {window + b*w8:.4g} - {window + (b+1)*w8:.4g} | {a_:.1f} | {c_:.1f} | {c_ - a_:.1f} | {i_:.1f} |")

table = "\n".join(out)
print()
print(table)

if write_results == "1":
    cpu = "unknown"
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip(); break
    lmp_ver = subprocess.run([lmp, "-h"], capture_output=True, text=True).stdout.strip().splitlines()
    lmp_ver = next((l.strip() for l in lmp_ver if "Large-scale" in l), "?")
    try:
        deb = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "lammps"], capture_output=True, text=True).stdout.strip()
    except OSError:
        deb = "?"
    try:
        rev = subprocess.run(["git", "-C", os.path.dirname(results_path), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", os.path.dirname(results_path), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        rev += " (with uncommitted changes)" if dirty else ""
    except OSError:
        rev = "?"
    load = open("/proc/loadavg").read().split()[:3]
    with open(results_path, "w") as f:
        f.write("# mrf vs LAMMPS on the paper DEM-Stokes scene — measured results\n\n")
        f.write("Written by `benchmarks/peers/lammps/compare.sh`; do not edit by hand. Method and discussion: "
                "[docs/performance.md](../../../docs/performance.md).\n\n")
        f.write(f"- date: {datetime.datetime.now().astimezone().isoformat(timespec='seconds')}\n")
        f.write(f"- machine: {os.cpu_count()} logical CPUs (nproc), {cpu}; load average at the end {' '.join(load)} "
                f"(the machine is shared, so only ratios measured side by side are quoted)\n")
        f.write(f"- mrf: git {rev}, summary version {bm.get('version', '?')}, Release build, 1 OpenMP thread\n")
        f.write(f"- LAMMPS: {lmp_ver}, Debian package {deb}, serial (1 MPI rank, no accelerator suffix)\n")
        f.write(f"- scene: {os.path.relpath(scene, os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(results_path)))))}, "
                f"Mn = {float(mason):g}, {n_free} magnetic + {bm['n_wall']} wall spheres, dipole cut-off {par['dipole_cutoff']:.3g} m, "
                f"skin {par['skin']:.3g} m\n")
        f.write(f"- force-law check of the LAMMPS mapping (in.check_forces): max relative error {float(check_max):.1e}; "
                f"start-up check over the first 10 steps: max relative difference {startup_worst:.1e}\n\n")
        f.write(table + "\n\n")
        f.write("## Commands (as run, in this order)\n\n```\n")
        f.write("OMP_NUM_THREADS=1\n")
        f.write(open(f"{work}/commands.txt").read())
        f.write("```\n")
    print(f"\nwrote {results_path}")
EOF
