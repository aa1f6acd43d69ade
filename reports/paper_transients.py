#!/usr/bin/python3
"""What settles when, in the paper cell's long runs: the magnetic structure
(the dipole energy) against the wall stress and its parts, in strain bins.

A post-hoc diagnostic, not a rule: it reads the whole time series of runs
(timeseries.csv of their run folders, which the sweep archives do not keep:
they keep the averaging window only) and bins, for each run, the dipole
energy per sphere in units of the contact energy of two aligned spheres,
u = -U_dip / (N mu0 m^2 / (2 pi d^3)) with m = M V the sphere's moment and
d = 2R (REFERENCE.md §2: the head-to-tail pair at contact), beside the total
wall stress, its particle part and its fluid part. The binned table
(reports/study/paper/transients.csv) is small and committed; a run whose
folder is gone keeps its committed rows, so the table grows over sessions.

Two questions it answers (docs/study.md cites it):
- model 3 at Mn 0.1: does its structure settle later than model 1's, and
  where do the kept windows of its runs sit on that curve?
- the coupled models at Mn 1e-3: is the slow fall of the total within the
  one window (16-48) the structure's, or the carrier's part alone?

usage: reports/paper_transients.py [--runs out/sweeps] [--out reports/study/paper]
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study import COLOR, LABEL, MU0, read_rows, strain_bin  # noqa: E402

# (sweep folder, model, Mn, bin width in strain units): the runs this reads
GROUPS = [("paper_realistic", "dem_stokes", 0.1, 25), ("paper_mn01_states", "dem_stokes", 0.1, 25),
          ("paper_realistic", "demsph_dd", 0.1, 25), ("paper_mn01_coupled_seeds", "demsph_dd", 0.1, 25),
          ("paper_mn01_long", "demsph_dd", 0.1, 25),
          ("paper_realistic", "demsph_stokes", 1e-3, 4), ("paper_realistic", "demsph_dd", 1e-3, 4),
          ("paper_model1_seeds", "dem_stokes", 1e-3, 4), ("paper_realistic", "dem_stokes", 1e-3, 4),
          # Q1 of paper_model1_low_long.toml: its runs' 4-12 and 16-48 means from these 4-unit bins
          ("paper_model1_low_long", "dem_stokes", 1e-3, 4), ("paper_model1_low_long", "dem_stokes", 3e-4, 4),
          # the coupled models at Mn 1e-3 with the common EOS reference (paper_common_low.toml, session 40)
          ("paper_common_low", "demsph_stokes", 1e-3, 4), ("paper_common_low", "demsph_dd", 1e-3, 4)]
FIELDS = ["sweep", "model", "mason", "seed", "strain_lo", "strain_hi", "warmup_strain", "run_strain",
          "dipole_energy_per_sphere", "stress_total_Pa", "stress_particles_Pa", "stress_fluid_Pa"]


def arg(key, default):
    return sys.argv[sys.argv.index(key) + 1] if key in sys.argv else default


def unit_energy(summary):
    """mu0 m^2 / (2 pi d^3) times the sphere count (J): the contact energy of
    an aligned pair, per sphere."""
    r, m = summary["radius"], summary["magnetization"] * 4.0 / 3.0 * math.pi * summary["radius"] ** 3
    return summary["n_particles"] * MU0 * m * m / (2 * math.pi * (2 * r) ** 3)


def bin_run(sweep, model, mn, folder, width):
    summary = json.load(open(os.path.join(folder, "summary.json")))
    rows = read_rows(os.path.join(folder, "timeseries.csv"))
    unit = unit_energy(summary)
    out = []
    top = summary["strain"]
    for k in range(int(math.ceil(top / width - 1e-9))):
        lo, hi = k * width, min((k + 1) * width, top)
        def mean(key):
            return strain_bin(rows, key, lo, hi)
        if math.isnan(mean("stress_total_Pa")):
            continue
        out.append({"sweep": sweep, "model": model, "mason": f"{mn:g}", "seed": summary["seed"], "strain_lo": f"{lo:g}",
                    "strain_hi": f"{hi:g}", "warmup_strain": f"{summary['warmup_strain']:g}",
                    "run_strain": f"{top:g}", "dipole_energy_per_sphere": f"{-mean('energy_dipole_J') / unit:.5f}",
                    "stress_total_Pa": f"{mean('stress_total_Pa'):.2f}",
                    "stress_particles_Pa": f"{mean('stress_particles_Pa'):.2f}",
                    "stress_fluid_Pa": f"{mean('stress_fluid_Pa'):.2f}"})
    return out


def collect(runs, table):
    """Rows of every run folder found under runs; runs whose folder is gone
    keep their rows of the committed table."""
    old = read_rows(table) if os.path.exists(table) else []
    new, seen = [], set()
    for sweep, model, mn, width in GROUPS:
        base = os.path.join(runs, sweep, model)
        for name in sorted(os.listdir(base)) if os.path.isdir(base) else []:
            folder = os.path.join(base, name)
            if not name.startswith(f"mn_{mn:g}_seed_") or not os.path.exists(os.path.join(folder, "summary.json")):
                continue  # unfinished runs have no summary yet
            got = bin_run(sweep, model, mn, folder, width)
            new += got
            seen |= {(r["sweep"], r["model"], r["mason"], str(r["seed"])) for r in got}
    kept = [r for r in old if (r["sweep"], r["model"], r["mason"], str(r["seed"])) not in seen]
    return kept + new


def runs_of(rows, model, mn):
    by = {}
    for r in rows:
        if r["model"] == model and float(r["mason"]) == mn:
            by.setdefault((r["sweep"], int(r["seed"])), []).append(r)
    return by


def figure(rows, out):
    fig, axs = plt.subplots(1, 3, figsize=(16, 4.6))
    # (a) Mn 0.1: the structure of model 1 and model 3 against strain, each
    # run's kept window drawn thick
    for model in ("dem_stokes", "demsph_dd"):
        for i, ((sweep, seed), rs) in enumerate(sorted(runs_of(rows, model, 0.1).items())):
            mid = [(float(r["strain_lo"]) + float(r["strain_hi"])) / 2 for r in rs]
            u = [float(r["dipole_energy_per_sphere"]) for r in rs]
            w = float(rs[0]["warmup_strain"])
            axs[0].plot(mid, u, "-", color=COLOR[model], lw=0.8, alpha=0.6,
                        label=f"{LABEL[model]} (each seed)" if i == 0 else None)
            axs[0].plot([x for x in mid if x > w], [v for x, v in zip(mid, u) if x > w], "-", color=COLOR[model], lw=2.2,
                        alpha=0.8, label="its averaging window" if i == 0 and model == "dem_stokes" else None)
            axs[1].plot([x for x in mid if x > w], [float(r["stress_total_Pa"]) for x, r in zip(mid, rs) if x > w],
                        "o-", ms=3, color=COLOR[model], lw=1, alpha=0.7,
                        label=f"{LABEL[model]} (each seed's window)" if i == 0 else None)
    axs[0].set(xlabel="strain", ylabel="-U_dip / (N mu0 m^2 / (2 pi d^3))",
               title="Mn 0.1: magnetic structure (dipole energy per sphere)")
    axs[1].set(xlabel="strain", ylabel="total wall stress (Pa), 25-strain bins", title="Mn 0.1: the windows' stress")
    # (c) Mn 1e-3, coupled: the structure settles, the carrier's part goes on
    ax2 = axs[2].twinx()
    for model in ("demsph_stokes", "demsph_dd"):
        for i, ((sweep, seed), rs) in enumerate(sorted(runs_of(rows, model, 1e-3).items())):
            if float(rs[0]["run_strain"]) < 48:
                continue
            mid = [(float(r["strain_lo"]) + float(r["strain_hi"])) / 2 for r in rs]
            axs[2].plot(mid, [float(r["stress_fluid_Pa"]) for r in rs], "o-", ms=3, color=COLOR[model],
                        label=f"{LABEL[model]}: fluid part" if i == 0 else None)
            axs[2].plot(mid, [float(r["stress_particles_Pa"]) for r in rs], "s--", ms=3, color=COLOR[model],
                        alpha=0.6, label=f"{LABEL[model]}: particle part" if i == 0 else None)
            ax2.plot(mid, [float(r["dipole_energy_per_sphere"]) for r in rs], ":", color=COLOR[model], lw=1.5)
    axs[2].axvline(16, color="gray", lw=0.8, ls="--")
    axs[2].set(xlabel="strain", ylabel="wall stress part (Pa), 4-strain bins",
               title="Mn 1e-3, 48-unit runs (dotted: dipole energy, right axis)")
    ax2.set_ylabel("-U_dip / (N mu0 m^2 / (2 pi d^3))")
    for ax in axs:
        ax.legend(fontsize=7)
    fig.savefig(os.path.join(out, "transients.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


def main():
    runs, out = arg("--runs", os.path.join("out", "sweeps")), arg("--out", os.path.join("reports", "study", "paper"))
    table = os.path.join(out, "transients.csv")
    rows = collect(runs, table)
    if not rows:
        print(f"paper_transients: no finished run folder under {runs} and no {table}", file=sys.stderr)
        return 1
    with open(table, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    figure(rows, out)
    print(f"paper_transients: {len({(r['sweep'], r['model'], r['mason'], r['seed']) for r in rows})} runs -> {table}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
