#!/usr/bin/python3
"""Work-precision of the DEM-Stokes integrators on the small scene at Mn = 1e-2.

Runs `mrf run experiments/scenes/small_dem_stokes.toml` one after the other
(one OpenMP thread each, so the wall times compare), writes
implicit_small_scene.csv and implicit_small_scene.png here:

  * the Y-converged reference: explicit verlet_exp at the real modulus of iron,
    Y = 200 GPa, over the same strain window as the other runs (the stress of
    this scene drifts up over tens of strain units, REFERENCE.md §8, so only
    equal windows compare);
  * explicit soft-Y runs (verlet_exp at 0.2, 2, 20 GPa), explicit stiff-Y
    (200 GPa) and implicit stiff-Y runs (200 GPa, three error tolerances);
  * error of the steady stress_total against the reference, with the block-
    averaging errors of both combined, against the wall time of the stepping
    normalised to one strain unit;
  * the side-by-side timing of one strain unit at Y = 200 GPa, implicit vs the
    best explicit scheme (verlet_exp: its contact limit is 17x that of the
    explicit overdamped scheme here).

Usage: reports/work_precision/implicit_small_scene.py BUILD_DIR [--quick]
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(ROOT, "experiments", "scenes", "small_dem_stokes.toml")


def run(build, label, sets):
    out = tempfile.mkdtemp(prefix="mrf_wp_")
    cmd = [os.path.join(build, "mrf"), "run", SCENE, "--quiet", "--out", out, "--set", "numerics.threads=1"]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        j = json.load(f)
    j["label"] = label
    print(f"{label:28s} Y={j['youngs_modulus']:.3g} {j['integrator']:10s} strain {j['strain']:.1f}: "
          f"stress {j['stress_total']:.1f} +- {j['stress_total_err']:.1f} Pa, {j['steps']} steps, "
          f"{j['wall_seconds']:.2f} s, max overlap/R {j['max_overlap_over_radius']:.3g}", flush=True)
    return j


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build")
    quick = "--quick" in sys.argv
    strain, warm = ("3", "1") if quick else ("6", "2")
    drive = [f"drive.strain={strain}", f"drive.warmup_strain={warm}"]
    rows = []
    # Side by side: one strain unit at Y = 200 GPa, implicit vs the best explicit.
    one = ["drive.strain=1", "drive.warmup_strain=0.3"]
    t_exp = run(build, "timing verlet_exp 200GPa", one + ["numerics.integrator=verlet_exp"])
    t_imp = run(build, "timing implicit 200GPa", one + ["numerics.integrator=implicit"])
    rows += [t_exp, t_imp]
    for y in ["0.2 GPa", "2 GPa", "20 GPa", "200 GPa"]:
        rows.append(run(build, f"explicit {y}", drive + ["numerics.integrator=verlet_exp",
                                                          f'contact.youngs_modulus="{y}"']))
    ref = rows[-1]
    for y in ["2 GPa", "20 GPa"]:
        rows.append(run(build, f"implicit {y}", drive + ["numerics.integrator=implicit",
                                                          f'contact.youngs_modulus="{y}"']))
    rows.append(run(build, "implicit 200 GPa", drive + ["numerics.integrator=implicit"]))

    path_csv = os.path.join(HERE, "implicit_small_scene.csv")
    keys = ["label", "integrator", "youngs_modulus", "strain", "warmup_strain", "stress_total", "stress_total_err",
            "steps", "wall_seconds", "max_overlap_over_radius", "implicit_dt_mean", "implicit_rejected_steps",
            "implicit_newton_iterations", "implicit_linear_iterations", "implicit_newton_failures"]
    with open(path_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys + ["seconds_per_strain", "error_vs_reference_Pa", "error_bar_Pa"])
        for r in rows:
            err = abs(r["stress_total"] - ref["stress_total"])
            bar = math.hypot(r["stress_total_err"], ref["stress_total_err"]) if r is not ref else r["stress_total_err"]
            w.writerow([r.get(k, "") for k in keys] +
                       [r["wall_seconds"] / r["strain"], err if r is not ref else 0.0, bar])
    print(f"timing, one strain unit at 200 GPa: verlet_exp {t_exp['wall_seconds']:.2f} s, implicit "
          f"{t_imp['wall_seconds']:.2f} s, ratio {t_exp['wall_seconds'] / t_imp['wall_seconds']:.2f}")

    fig, ax = plt.subplots(figsize=(5.2, 3.8), dpi=110)
    styles = {"explicit": ("o", "tab:blue"), "implicit": ("s", "tab:red")}
    for r in rows[2:]:
        kind = "implicit" if r["integrator"] == "implicit" else "explicit"
        stiff = r["youngs_modulus"] >= 1e11
        m, c = styles[kind]
        err = abs(r["stress_total"] - ref["stress_total"])
        bar = math.hypot(r["stress_total_err"], ref["stress_total_err"])
        x = r["wall_seconds"] / r["strain"]
        if r is ref:
            ax.axvline(x, color=c, ls="--", lw=1)
            ax.annotate("reference (explicit 200 GPa)", (x, 3.0), fontsize=7, rotation=90, ha="right")
            continue
        ax.errorbar(x, max(err, 3.0), yerr=[[min(bar, max(err, 3.0) - 1.0)], [bar]], fmt=m, color=c,
                    mfc=c if stiff else "white", capsize=2)
        ax.annotate(f"{r['youngs_modulus'] / 1e9:g} GPa", (x, max(err, 3.0)), textcoords="offset points",
                    xytext=(4, 4), fontsize=7)
    ax.errorbar([], [], fmt="o", color="tab:blue", mfc="white", label="explicit verlet_exp, soft Y")
    ax.errorbar([], [], fmt="o", color="tab:blue", label="explicit verlet_exp, Y = 200 GPa")
    ax.errorbar([], [], fmt="s", color="tab:red", mfc="white", label="implicit, soft Y")
    ax.errorbar([], [], fmt="s", color="tab:red", label="implicit, Y = 200 GPa")
    ax.axhline(ref["stress_total_err"], color="gray", ls=":", lw=1, label="reference error bar")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per strain unit (s, 1 thread)")
    ax.set_ylabel("|stress_total - reference| (Pa)")
    ax.set_title(f"small scene, Mn = 1e-2; reference {ref['stress_total']:.0f} ± {ref['stress_total_err']:.0f} Pa",
                 fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "implicit_small_scene.png"))
    print("wrote", path_csv)


if __name__ == "__main__":
    main()
