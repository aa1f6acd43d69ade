#!/usr/bin/env python3
"""Sensitivity table: each variant's steady stress against the baseline run
(folder base_seed1), with the difference in units of the combined standard
error. usage: scaling_table.py RUNS_DIR OUT.md [TITLE]"""
import json
import math
import pathlib
import sys

src, dst = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
title = sys.argv[3] if len(sys.argv) > 3 else "Parameter scaling, small DEM-Stokes scene"
runs = {p.parent.name: json.loads(p.read_text()) for p in sorted(src.glob("*/summary.json"))}
base = runs["base_seed1"]
keys = [("stress_total", "tau total"), ("stress_particles", "tau particles (wall)"),
        ("stress_virial", "virial (particles)")]
out = [f"# {title}", "",
       f"Mn = {base['mason']:.3g} (Mn = 9 eta gdot / (2 mu0 M^2)), strain {base['strain']}, "
       f"warm-up {base['warmup_strain']}. Differences are given in units of the combined "
       "standard error sqrt(e1^2 + e2^2) of the two runs (|d| < 2: no detectable change).", ""]
head = "| run | Y (Pa) | rho_p (kg/m^3) | cutoff (um) | box ly x lz (um) | St | max h/R | dt (s) | " + " | ".join(
    f"{label} (Pa) | d" for _, label in keys) + " | wall s |"
out += [head, "|" + "---|" * (head.count("|") - 1)]
for name, s in runs.items():
    cells = []
    for k, _ in keys:
        e = math.hypot(s[k + "_err"], base[k + "_err"])
        d = (s[k] - base[k]) / e if name != "base_seed1" and e > 0 else 0.0
        cells.append(f"{s[k]:.4g} ± {s[k + '_err']:.2g} | {d:+.1f}")
    cut = s.get("dipole_cutoff", float("nan")) * 1e6
    box = f"{s.get('box_ly', float('nan')) * 1e6:.0f} x {s.get('box_lz', float('nan')) * 1e6:.0f}"
    out.append(f"| {name} | {s['youngs_modulus']:.3g} | {s['particle_density']:.4g} | {cut:.3g} | {box} | "
               f"{s['stokes_number']:.2g} | {s['max_overlap_over_radius']:.2g} | {s['dt']:.3g} | "
               + " | ".join(cells) + f" | {s['wall_seconds']:.0f} |")
dst.write_text("\n".join(out) + "\n")
