#!/usr/bin/python3
"""The SPH carrier's EOS reference on the small cell, across Mn
(experiments/sweeps/small_eos_reference.toml, its reading fixed there before
any run).

usage: small_eos.py [SWEEP_DIR] [OUT_DIR]
  defaults: out/sweeps/small_eos_reference, reports/study/small_eos

Reads every finished run's summary.json under SWEEP_DIR and writes
OUT_DIR/runs.csv (the fields used, one row a run), OUT_DIR/small_eos.md and
OUT_DIR/small_eos.png. The committed runs.csv is read first and a run found
under SWEEP_DIR adds or replaces its row, so the table regenerates from the
repository alone and grows across machines.

Per model and Mn, each reference's seed mean with error
max(sqrt(sum err^2) / n, seed standard deviation / sqrt(n)); the shift is
common minus start, in per cent of start and in combined standard errors.
"""
import csv
import glob
import json
import math
import os
import statistics
import sys
from collections import defaultdict

DRIFT_Z, MSER_MAX = 3.0, 0.2
FIELDS = ["model", "variant", "mason", "seed", "stress_total", "stress_total_err", "stress_total_drift_z",
          "steady_mser_discard_fraction", "stress_fluid", "stress_fluid_err", "stress_particles",
          "stress_particles_err", "sph_wall_layer_fraction_end", "cpu_seconds", "wall_seconds"]


def from_runs(sweep_dir):
    out = []
    for p in sorted(glob.glob(os.path.join(sweep_dir, "*", "*", "mn_*_seed_*", "summary.json"))):
        s = json.load(open(p))
        model, variant = p.split(os.sep)[-4], p.split(os.sep)[-3]
        row = {k: s.get(k, "") for k in FIELDS}
        row.update(model=model, variant=variant)
        out.append(row)
    return out


def num(r, k):
    try:
        return float(r[k])
    except (KeyError, ValueError, TypeError):
        return float("nan")


def steady(r):
    return abs(num(r, "stress_total_drift_z")) < DRIFT_Z and num(r, "steady_mser_discard_fraction") < MSER_MAX


def combine(runs, key):
    """Seed mean and its error: max(within-run / n, seed scatter / sqrt(n))."""
    v = [num(r, key) for r in runs]
    e = [num(r, key + "_err") for r in runs]
    n = len(v)
    within = math.sqrt(sum(x * x for x in e)) / n
    scatter = statistics.stdev(v) / math.sqrt(n) if n > 1 else 0.0
    err = max(within, scatter)
    return statistics.fmean(v), err


def shift(a, b):
    """common minus start: per cent of start, combined standard errors."""
    d = b[0] - a[0]
    se = math.hypot(a[1], b[1])
    return 100 * d / a[0], d / se if se > 0 else float("nan")


def plot(shifts, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 3, figsize=(10, 3.4))
    for ax, part in zip(axs, ["total", "fluid", "particles"]):
        for i, model in enumerate(sorted({m for m, _, _ in shifts})):
            pts = sorted((mn, v) for (m, mn, p), v in shifts.items() if m == model and p == part)
            if not pts:
                continue
            x = [mn * (1.08 if i else 1 / 1.08) for mn, _ in pts]
            ax.errorbar(x, [v[0] for _, v in pts], yerr=[v[1] for _, v in pts], fmt="o", capsize=3,
                        label=model)
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("Mn (realistic path, 1e3 1/s)")
        ax.set_title(f"{part}: common - start", fontsize=9)
    axs[0].set_ylabel("shift (% of start)")
    axs[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    sweep_dir = argv[1] if len(argv) > 1 else os.path.join(root, "out", "sweeps", "small_eos_reference")
    out_dir = argv[2] if len(argv) > 2 else os.path.join(here, "study", "small_eos")
    os.makedirs(out_dir, exist_ok=True)
    runs_csv = os.path.join(out_dir, "runs.csv")
    # The committed runs, with any finished run under SWEEP_DIR added or
    # replacing its row: the sweep spans machines whose run folders are lost.
    key = lambda r: (r["model"], r["variant"], float(r["mason"]), int(r["seed"]))
    runs = {key(r): r for r in csv.DictReader(open(runs_csv))} if os.path.exists(runs_csv) else {}
    if os.path.isdir(sweep_dir):
        runs.update({key(r): r for r in from_runs(sweep_dir)})
        with open(runs_csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, FIELDS)
            w.writeheader()
            w.writerows(runs[k] for k in sorted(runs))
    runs = list(runs.values())
    groups = defaultdict(list)
    for r in runs:
        groups[(r["model"], float(r["mason"]), r["variant"])].append(r)
    lines = ["# The SPH carrier's EOS reference on the small cell (sessions 37-38)", "",
             "experiments/sweeps/small_eos_reference.toml (design and reading fixed before its runs): small cell "
             "(375 spheres, 160 SPH particles), realistic path (1e3 1/s, M varied), auto integration, one thread. "
             "`start`: each SPH particle's intrinsic density at the start is its EOS reference (the default); "
             "`common`: the fluid density for every particle. Seed means in Pa, error max(within-run / n, seed "
             "scatter / sqrt(n)); shift = common - start in per cent of start and in combined standard errors "
             "(sigma). 'steady' counts runs passing drift |z| < 3 and MSER-5 < 0.2; 'layer' is the mean "
             "sph_wall_layer_fraction_end. Generated by reports/small_eos.py.", "",
             "| model | Mn | seeds (start/common) | steady | total start | total common | shift total | "
             "shift fluid part | shift particle part | layer start / common |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    shifts = {}
    missing = []
    for model, mn in sorted({(m, mn) for m, mn, _ in groups}):
        a, b = groups.get((model, mn, "start"), []), groups.get((model, mn, "common"), [])
        if not a or not b:
            missing.append(f"{model} Mn {mn:g}: {len(a)} start, {len(b)} common")
            continue
        cells = []
        for part, key in [("total", "stress_total"), ("fluid", "stress_fluid"), ("particles", "stress_particles")]:
            ca, cb = combine(a, key), combine(b, key)
            pct, sig = shift(ca, cb)
            err_pct = 100 * math.hypot(ca[1], cb[1]) / abs(ca[0]) if ca[0] else float("nan")
            shifts[(model, mn, part)] = (pct, err_pct)
            cells.append((ca, cb, pct, sig))
        layer = [statistics.fmean(num(r, "sph_wall_layer_fraction_end") for r in g) for g in (a, b)]
        (ta, tb, tp, ts), (_, _, fp, fs), (_, _, pp, ps) = cells
        lines.append(f"| {model} | {mn:g} | {len(a)}/{len(b)} | {sum(map(steady, a))}/{sum(map(steady, b))} | "
                     f"{ta[0]:.1f} ± {ta[1]:.1f} | {tb[0]:.1f} ± {tb[1]:.1f} | {tp:+.1f} % ({ts:+.1f} sigma) | "
                     f"{fp:+.1f} % ({fs:+.1f}) | {pp:+.1f} % ({ps:+.1f}) | {layer[0]:.3f} / {layer[1]:.3f} |")
    if missing:
        lines += ["", "Not yet comparable (a side without runs): " + "; ".join(missing) + "."]
    cpu = sum(num(r, "cpu_seconds") for r in runs if num(r, "cpu_seconds") == num(r, "cpu_seconds"))
    lines += ["", f"{len(runs)} runs, {cpu / 3600:.2f} CPU hours in all.", "", "![shifts](small_eos.png)", ""]
    open(os.path.join(out_dir, "small_eos.md"), "w").write("\n".join(lines))
    if shifts:
        plot(shifts, os.path.join(out_dir, "small_eos.png"))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
