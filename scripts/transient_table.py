#!/usr/bin/env python3
"""Block means per strain unit of a run's time series, to see how long its
start-up transient lasts (issue: the paper's study at the paper's scale,
the strain per Mn chosen by rule from measured transients).

Usage: scripts/transient_table.py RUN_DIR [RUN_DIR ...] > table.md
Each RUN_DIR holds timeseries.csv (finished or still running) and, when
finished, summary.json. Columns: the particle wall stress and the volume
(virial) particle stress per unit of strain, Pa.
"""
import csv, json, pathlib, sys


def blocks(path):
    rows = list(csv.DictReader(open(path)))
    out, edge, wall, vir, w = [], 1.0, 0.0, 0.0, 0.0
    last = 0.0
    for r in rows:
        s = float(r["strain"])
        if s > edge and w > 0:
            out.append((edge, wall / w, vir / w))
            edge, wall, vir, w = edge + 1.0, 0.0, 0.0, 0.0
        dw = s - last  # rows are time-weighted means over their interval
        last = s
        wall += dw * float(r["stress_particles_Pa"])
        vir += dw * (float(r["stress_virial_magnetic_Pa"]) + float(r["stress_virial_contact_Pa"]))
        w += dw
    return out, last


for d in map(pathlib.Path, sys.argv[1:]):
    b, reached = blocks(d / "timeseries.csv")
    done = (d / "summary.json").exists()
    print(f"### {d.parent.name}/{d.name}: strain {reached:.1f}{'' if done else ' (still running)'}\n")
    if done:
        s = json.loads((d / "summary.json").read_text())
        print(f"{s['seconds_per_strain']:.0f} s per strain unit, {s['integrator']}, M = {s['magnetization']:.4g} A/m\n")
    print("| strain | particle wall stress (Pa) | particle virial stress (Pa) |")
    print("|---|---|---|")
    for e, m, v in b:
        print(f"| {e - 1:.0f}-{e:.0f} | {m:.0f} | {v:.0f} |")
    print()
