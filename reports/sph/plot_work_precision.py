#!/usr/bin/python3
"""Plot the SPH work-precision CSV written by the Slow test
SphWorkPrecisionSlow.WriteCsv (verification/fluid/test_sph_work_precision.cpp).

usage: /usr/bin/python3 reports/sph/plot_work_precision.py [CSV] [PNG]
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "work_precision.csv")
dst = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "work_precision.png")

with open(src) as f:
    rows = list(csv.DictReader(line for line in f if not line.startswith("#")))

series = {}
for r in rows:
    key = (r["scheme"], float(r["dt_over_viscous_limit"]))
    series.setdefault(key, []).append(r)

fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
panels = [("wall_s_startup", "err_startup", "start-up, t = 0.05 L²/ν"),
          ("wall_s_steady", "err_steady", "near steady, t = 0.25 L²/ν")]
for ax, (tcol, ecol, title) in zip(axes, panels):
    for (scheme, factor), rs in sorted(series.items()):
        rs = sorted(rs, key=lambda r: int(r["n_across"]))
        t = [float(r[tcol]) for r in rs]
        e = [float(r[ecol]) for r in rs]
        style = "o-" if scheme == "explicit" else "s--"
        ax.loglog(t, e, style, label=f"{scheme}, dt = {factor:g} × viscous limit")
        for r, ti, ei in zip(rs, t, e):
            ax.annotate(r["n_across"], (ti, ei), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("wall time (s, 1 thread)")
    ax.set_ylabel("relative L2 error of v_z")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=8)
fig.suptitle("SPH start-up Couette: work–precision (labels: particles across the gap)")
fig.tight_layout()
fig.savefig(dst, dpi=120)
print(dst)
