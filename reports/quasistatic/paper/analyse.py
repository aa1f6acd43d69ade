#!/usr/bin/python3
"""The paper cell's quasi-static (AQS) runs (issue 17): window means with
block-average errors, the periodic-orbit test, results.csv for the study
report (reports/paper_study.py) and the figure aqs_paper.png.

Usage: /usr/bin/python3 reports/quasistatic/paper/analyse.py NAME=RUN_DIR[:FROM[:TO]] ... [--scale PA]
                                                            [--label NAME=TEXT]...
  --label: what the run's summary.json does not say (e.g. its Young's modulus),
  put first in its note; the increment, tolerance, cut-off and seed come from
  summary.json, and a lock on a short repeat (deviation < 1 %) is noted.
  RUN_DIR may also be a committed per-minimum CSV (e.g. headline_quasistatic.csv
  beside this script): a finished run, its settings then given by --label and
  its stress scale by --scale or another run.
  The first run is the headline. RUN_DIR holds quasistatic.csv and summary.json
  of `mrf quasistatic` (a run still going has a partial CSV and no summary: its
  stress scale is then taken from the headline's, or from --scale). FROM/TO:
  the strain window of the mean (default: the run's warm-up from summary.json,
  or 0.2, to its last minimum).
Also the shortest repeat over the last lz/gap of strain: the lag (in minima,
up to 20) at which the stress repeats best, and how well.
Writes results.csv, <headline>_quasistatic.csv (a copy of its per-minimum CSV)
and aqs_paper.png beside this script.

Errors: the block average of the window (the largest standard error over
blocking levels with at least 8 blocks; below 16 minima the plain standard
error). When the window repeats itself with the walls' period lz/gap (0.8 on
the paper cell) the block error is no error bar: the report then quotes the
scatter between realisations (seeds, increments, Y) instead.
"""
import csv
import json
import math
import os
import shutil
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
PERIOD = 120.0 / 150.0  # lz / gap of the paper cell


def block_error(y):
    n = len(y)
    if n < 2:
        return float("nan")
    mean = sum(y) / n
    plain = math.sqrt(sum((v - mean) ** 2 for v in y) / (n - 1) / n)
    if n < 16:
        return plain
    best, b = plain, 1
    while n // (2 * b) >= 8:
        b *= 2
        m = n // b
        blocks = [sum(y[i * b:(i + 1) * b]) / b for i in range(m)]
        bm = sum(blocks) / m
        best = max(best, math.sqrt(sum((v - bm) ** 2 for v in blocks) / (m - 1) / m))
    return best


def periodic(strain, wall, frm):
    """Largest |w(s + period) - w(s)| / max|w| over the window, or None if shorter than two periods."""
    idx = {round(s, 9): w for s, w in zip(strain, wall)}
    pairs = [(w, idx.get(round(s + PERIOD, 9))) for s, w in zip(strain, wall) if s >= frm - 1e-12]
    pairs = [(a, b) for a, b in pairs if b is not None]
    if not pairs:
        return None
    scale = max(max(abs(a), abs(b)) for a, b in pairs)
    return max(abs(a - b) for a, b in pairs) / scale


def shortest_repeat(strain, wall, max_lag=20):
    """Over the last lz/gap of strain: the lag (in minima) whose largest |w(k) - w(k - lag)| is smallest,
    and that deviation / max|w|. A small value is an orbit locked on the wall lattice (README §5)."""
    n = len(wall)
    last = [k for k in range(n) if strain[k] >= strain[-1] - PERIOD]
    best = None
    for lag in range(1, max_lag + 1):
        ks = [k for k in last if k - lag >= 0]
        if not ks:
            break
        scale = max(abs(wall[k]) for k in ks)
        dev = max(abs(wall[k] - wall[k - lag]) for k in ks) / scale
        if best is None or dev < best[1]:
            best = (lag, dev)
    return best


def main(argv):
    labels = dict(argv[i + 1].split("=", 1) for i, a in enumerate(argv) if a == "--label")
    specs = [a for i, a in enumerate(argv[1:], 1) if "=" in a and argv[i - 1] != "--label"]
    if not specs:
        print(__doc__)
        return 2
    runs = []
    scale = float(argv[argv.index("--scale") + 1]) if "--scale" in argv else None
    for spec in specs:
        name, rest = spec.split("=", 1)
        parts = rest.split(":")
        d = parts[0]
        committed = d.endswith(".csv")  # a finished run's per-minimum CSV, as committed beside this script
        csv_path = d if committed else os.path.join(d, "quasistatic.csv")
        rows = list(csv.DictReader(open(csv_path)))
        summ = os.path.join(d, "summary.json")
        s = {} if committed or not os.path.exists(summ) else json.load(open(summ))
        strain = [float(r["strain"]) for r in rows]
        wall = [float(r["stress_wall"]) for r in rows]
        frm = float(parts[1]) if len(parts) > 1 else s.get("steady_from_strain", 0.2)
        to = float(parts[2]) if len(parts) > 2 else strain[-1]
        win = [w for x, w in zip(strain, wall) if frm - 1e-12 <= x <= to + 1e-12]
        if s.get("stress_scale"):
            scale = scale or s["stress_scale"]
        runs.append(dict(name=name, dir=d, strain=strain, wall=wall, frm=frm, to=to, n=len(win),
                         mean=sum(win) / len(win) if win else float("nan"), err=block_error(win),
                         dev=periodic(strain, wall, frm), rep=shortest_repeat(strain, wall), done=bool(s) or committed,
                         summary=s, scale=s.get("stress_scale"), csv=csv_path,
                         iters=sum(int(r["iterations"]) for r in rows), seconds=s.get("wall_seconds")))
    if scale is None:
        raise SystemExit("no summary.json among the runs: no stress scale (phi mu0 M^2)")
    out = os.path.join(here, "results.csv")
    with open(out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "stress_over_phi_mu0_m2", "err", "mean_Pa", "err_Pa", "from_strain", "to_strain",
                    "minima_in_window", "periodic_deviation", "repeat_lag", "repeat_deviation", "finished",
                    "note"])
        for r in runs:
            sc = r["scale"] or scale
            dev = "" if r["dev"] is None else f"{r['dev']:.2e}"
            parts = [labels[r["name"]]] if r["name"] in labels else []
            if r["summary"]:
                q = r["summary"]
                parts.append(f"d {q['strain_increment']:g}, tol {q['force_tol_over_f0']:g} F0, "
                             f"r_c {q['dipole_cutoff'] * 1e6:g} um, seed {q['seed']}")
            parts.append(f"window {r['frm']:g}-{r['to']:g}")
            if r["dev"] is not None and r["dev"] < 1e-6:
                parts.append("periodic orbit (lz/gap): block error is no error bar")
            elif r["rep"] and r["rep"][1] < 1e-2:
                parts.append(f"repeats every {r['rep'][0]} minima at the end (deviation {r['rep'][1]:.1e}): "
                             "block error of one realisation")
            if not r["done"]:
                parts.append("still running (partial CSV)")
            note = "; ".join(parts)
            w.writerow([r["name"], f"{r['mean'] / sc:.6g}", f"{r['err'] / sc:.3g}", f"{r['mean']:.6g}",
                        f"{r['err']:.3g}", f"{r['frm']:g}", f"{r['to']:g}", r["n"], dev,
                        r["rep"][0] if r["rep"] else "", f"{r['rep'][1]:.2e}" if r["rep"] else "", int(r["done"]),
                        note])
    head = runs[0]
    target = os.path.join(here, f"{head['name']}_quasistatic.csv")
    if os.path.abspath(head["csv"]) != os.path.abspath(target):
        shutil.copy(head["csv"], target)

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for i, r in enumerate(runs):
        ax.plot(r["strain"], [v / scale for v in r["wall"]], lw=1.2 if i == 0 else 0.7, color=f"C{i}",
                label=f"{r['name']}: {r['mean'] / scale:.4f} ± {r['err'] / scale:.4f} over {r['frm']:g}-{r['to']:g}")
    for k in range(1, 5):
        ax.axvline(k * PERIOD, color="grey", lw=0.5, ls=":")
    ax.set(xlabel="strain", ylabel="wall shear stress / (phi mu0 M^2)",
           title="AQS, paper cell (4125 spheres, 150 x 50 x 120 um); dotted: the walls' period lz/gap")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(here, "aqs_paper.png"), dpi=130)
    print(f"-> {out}, {os.path.join(here, 'aqs_paper.png')}")
    for r in runs:
        print(f"{r['name']}: {r['mean']:.1f} ± {r['err']:.1f} Pa = {r['mean'] / scale:.5f} phi mu0 M^2 over "
              f"{r['frm']:g}-{r['to']:g} ({r['n']} minima), periodic deviation {r['dev']}, "
              f"shortest repeat over the last lz/gap: lag {r['rep'][0] if r['rep'] else '-'} "
              f"(deviation {r['rep'][1] if r['rep'] else float('nan'):.2e}), "
              f"{r['iters']} FIRE iterations, {'finished' if r['done'] else 'running'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
