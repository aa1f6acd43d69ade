#!/usr/bin/python3
"""Figure of reports/quasistatic/README.md: AQS wall stress against strain for the
small cell (headline run), and its steady mean beside the chain model (REFERENCE
TEST 1.5) and the dynamic model-1 stresses of reports/study/flow_curves.csv.

Usage: /usr/bin/python3 reports/quasistatic/plot.py   (from the repository root or anywhere)
Reads  reports/quasistatic/headline_quasistatic.csv  (per minimum, copied from the run)
       reports/quasistatic/variants_wall.csv         (run,strain,stress_wall of the other runs)
       reports/quasistatic/results.csv               (window means of all runs)
       reports/study/flow_curves.csv
Writes reports/quasistatic/aqs_small.png
"""
import csv, math, os
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))
MU0 = 4e-7 * math.pi
M = 1e6
PHI = 0.3
SCALE_NOMINAL = PHI * MU0 * M**2  # phi mu0 M^2 for the dynamic study (nominal phi 0.3)

rows = list(csv.DictReader(open(os.path.join(here, "headline_quasistatic.csv"))))
strain = [float(r["strain"]) for r in rows]
wall = [float(r["stress_wall"]) for r in rows]
res = {r["run"]: r for r in csv.DictReader(open(os.path.join(here, "results.csv")))}
head = res["headline"]
scale = float(head["stress_scale_Pa"])  # phi mu0 M^2 of the cell as built (N V_p / V)
mean, err, frm = float(head["mean_Pa"]), float(head["err_Pa"]), float(head["from_strain"])

flow = [r for r in csv.DictReader(open(os.path.join(here, "..", "study", "flow_curves.csv")))
        if r["model"] == "dem_stokes" and float(r["mason"]) in (1e-3, 1e-2)]

fig, (ax, cx, bx) = plt.subplots(1, 3, figsize=(16, 4.8), gridspec_kw={"width_ratios": [1.8, 1.4, 1]})
ax.plot(strain, [w / 1e3 for w in wall], lw=0.7, color="C0", label="wall stress at each minimum")
ax.axhspan((mean - err) / 1e3, (mean + err) / 1e3, color="C1", alpha=0.35)
ax.hlines(mean / 1e3, frm, strain[-1], color="C1", lw=2,
          label=f"mean over one period (0.1-0.5): {mean:.0f} Pa; band: realisation scatter ± {err:.0f} Pa")
for k in range(1, 5):
    ax.axvline(0.1 + 0.4 * k, color="grey", lw=0.5, ls=":")
ax.set_xlabel("strain")
ax.set_ylabel("wall shear stress (kPa)")
ax.set_title(f"AQS, small cell (375 spheres), {head['label']}", fontsize=9)
ax.legend(fontsize=8, loc="upper right")
sec = ax.secondary_yaxis("right", functions=(lambda k: k * 1e3 / scale, lambda s: s * scale / 1e3))
sec.set_ylabel(r"$\tau/(\phi\mu_0 M^2)$")

var = {}
for r in csv.DictReader(open(os.path.join(here, "variants_wall.csv"))):
    var.setdefault(r["run"], ([], []))
    var[r["run"]][0].append(float(r["strain"])); var[r["run"]][1].append(float(r["stress_wall"]) / 1e3)
cx.plot(strain, [w / 1e3 for w in wall], lw=1.2, color="C0", label="headline (d 1e-2, 2 GPa, seed 1)")
for i, (name, (s_, w_)) in enumerate(var.items()):
    cx.plot(s_, w_, lw=0.8, color=f"C{i + 2}", label=name)
cx.set_xlim(0, 0.5)
cx.set_xlabel("strain"); cx.set_ylabel("wall shear stress (kPa)")
cx.set_title("variants (zoom)", fontsize=9)
cx.legend(fontsize=6, loc="upper right", ncol=2)

labels, vals, errs, cols = [], [], [], []
labels.append("AQS 2 GPa (headline)\nwall = virial"); vals.append(mean / scale); errs.append(err / scale); cols.append("C1")
for key, lab in (("Y20_w", "AQS 20 GPa, seed 1"), ("Y20s2_w", "AQS 20 GPa, seed 2")):
    if key in res:
        labels.append(lab); vals.append(float(res[key]["mean_Pa"]) / scale)
        errs.append(float(res[key]["err_Pa"]) / scale); cols.append("C5")
for r in flow:
    mn = float(r["mason"])
    tot, e, fl = float(r["stress_Pa"]), float(r["err_Pa"]), float(r["stress_fluid_Pa"])
    labels.append(f"model 1 total\nMn={mn:g}"); vals.append(tot / SCALE_NOMINAL); errs.append(e / SCALE_NOMINAL); cols.append("C0")
    labels.append(f"model 1 particles\nMn={mn:g}"); vals.append((tot - fl) / SCALE_NOMINAL); errs.append(e / SCALE_NOMINAL); cols.append("C2")
labels.append("chain model\n(TEST 1.5)"); vals.append(0.13738); errs.append(0); cols.append("C3")
y = list(range(len(labels)))
bx.barh(y, vals, xerr=errs, color=cols, alpha=0.8)
bx.axvspan(0.06, 0.13, color="grey", alpha=0.2, label="experiments 0.06-0.13")
bx.set_yticks(y); bx.set_yticklabels(labels, fontsize=7)
bx.set_xscale("log"); bx.set_xlabel(r"$\tau/(\phi\mu_0 M^2)$")
bx.legend(fontsize=7, loc="lower right")
bx.set_title("steady stress (dynamic: reports/study, Y = 20 GPa)", fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(here, "aqs_small.png"), dpi=130)
print("wrote", os.path.join(here, "aqs_small.png"))
