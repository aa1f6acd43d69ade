#!/usr/bin/env python3
"""Collect every summary.json under a directory into one Markdown table."""
import json
import pathlib
import sys

src, dst = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
rows = sorted((json.loads(p.read_text()) | {"dir": p.parent.name} for p in src.rglob("summary.json")),
              key=lambda s: (s["model"], s["mason"]))
head = ("| run | model | Mn | tau_total (Pa) | tau_particles (Pa) | tau_fluid (Pa) | virial (Pa) "
        "| wall - virial (Pa) | drift z | St | max h/R | integrator | dt (s) | steps | wall s |")
lines = ["# DEM-Stokes default runs", "",
         "Mason number Mn = 9 eta gdot / (2 mu0 M^2). Stresses are block averages over the "
         "strain after warm-up, with standard errors; drift z compares the two halves of the "
         "averaging window (|z| > 3 means the mean still moves).", "", head,
         "|" + "---|" * (head.count("|") - 1)]
for s in rows:
    lines.append(
        f"| {s['dir']} | {s['model']} | {s['mason']:.3g} | {s['stress_total']:.4g} ± {s['stress_total_err']:.2g} "
        f"| {s['stress_particles']:.4g} | {s['stress_fluid']:.4g} "
        f"| {s['stress_virial']:.4g} ± {s['stress_virial_err']:.2g} "
        f"| {s['stress_wall_minus_virial']:.3g} ± {s['stress_wall_minus_virial_err']:.2g} "
        f"| {s['stress_total_drift_z']:.2f} | {s['stokes_number']:.2g} | {s['max_overlap_over_radius']:.2g} "
        f"| {s['integrator']} | {s['dt']:.3g} | {s['steps']} | {s['wall_seconds']:.1f} |")
dst.write_text("\n".join(lines) + "\n")
