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
    (200 GPa), implicit runs at 2, 20, 200 GPa (implicit_tol 0.01, the
    default, order 2) and at 200 GPa with implicit_tol 0.005, 0.02, 0.05, and
    order 1 at 0.01 and 0.02; six seeds;
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


def mean_over_seeds(runs):
    """Seed mean of stress_total; its error from the seed scatter (n - 1 dof)
    and the mean block-averaging error, whichever is larger."""
    x = [r["stress_total"] for r in runs]
    n = len(x)
    m = sum(x) / n
    scatter = math.sqrt(sum((v - m) ** 2 for v in x) / (n - 1) / n) if n > 1 else 0.0
    block = math.sqrt(sum(r["stress_total_err"] ** 2 for r in runs)) / n
    return m, max(scatter, block), sum(r["wall_seconds"] / r["strain"] for r in runs) / n


def main():
    build = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else os.path.join(ROOT, "build")
    quick = "--quick" in sys.argv
    strain, warm = ("3", "1") if quick else ("6", "2")
    seeds = [1, 2] if quick else [1, 2, 3, 4, 5, 6]
    drive = [f"drive.strain={strain}", f"drive.warmup_strain={warm}"]
    runs = []
    # Side by side: one strain unit at Y = 200 GPa, implicit vs the best
    # explicit scheme, alternating, three times (the machine is shared).
    one = ["drive.strain=1", "drive.warmup_strain=0.3"]
    timing = []
    for rep in range(3):
        t_exp = run(build, f"timing verlet_exp 200GPa rep {rep + 1}", one + ["numerics.integrator=verlet_exp"])
        t_imp = run(build, f"timing implicit 200GPa rep {rep + 1}", one + ["numerics.integrator=implicit"])
        timing.append((t_exp, t_imp))
    # (group name, scheme, Y, implicit_tol, implicit_order); the implicit default is order 2, tol 0.01
    configs = [(f"verlet_exp {y}", "verlet_exp", y, None, None) for y in ["0.2 GPa", "2 GPa", "20 GPa", "200 GPa"]] + \
              [(f"implicit {y}", "implicit", y, "0.01", "2") for y in ["2 GPa", "20 GPa", "200 GPa"]] + \
              [(f"implicit 200 GPa tol {t}", "implicit", "200 GPa", t, "2") for t in ["0.005", "0.02", "0.05"]] + \
              [(f"implicit 200 GPa order 1 tol {t}", "implicit", "200 GPa", t, "1") for t in ["0.01", "0.02"]]
    groups = {}
    for name, scheme, y, tol, order in configs:
        for seed in seeds:
            sets = drive + [f"numerics.integrator={scheme}", f'contact.youngs_modulus="{y}"', f"scene.seed={seed}"]
            if tol:
                sets += [f"numerics.implicit_tol={tol}", f"numerics.implicit_order={order}"]
            r = run(build, f"{name} seed {seed}", sets)
            r["seed"] = seed
            r["implicit_tol"] = tol or ""
            runs.append(r)
            r["implicit_order"] = order or ""
            groups.setdefault((name, scheme, y, tol, order), []).append(r)
    ref_key = ("verlet_exp 200 GPa", "verlet_exp", "200 GPa", None, None)
    ref_m, ref_e, _ = mean_over_seeds(groups[ref_key])

    keys = ["label", "integrator", "youngs_modulus", "implicit_tol", "implicit_order", "seed", "strain", "warmup_strain",
            "stress_total", "stress_total_err", "steps", "wall_seconds", "max_overlap_over_radius",
            "implicit_dt_mean", "implicit_rejected_steps", "implicit_newton_failures",
            "implicit_newton_iterations", "implicit_linear_iterations"]
    with open(os.path.join(HERE, "implicit_small_scene_runs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(keys)
        for r in [t for pair in timing for t in pair] + runs:
            w.writerow([r.get(k, "") for k in keys])
    path_csv = os.path.join(HERE, "implicit_small_scene.csv")
    points = []
    with open(path_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["integrator", "youngs_modulus_Pa", "implicit_tol", "implicit_order", "seeds", "stress_total_mean_Pa",
                    "stress_total_err_Pa", "seconds_per_strain", "signed_error_vs_reference_Pa", "error_bar_Pa",
                    "max_overlap_over_radius"])
        for (name, scheme, y, tol, order), g in groups.items():
            m, e, sec = mean_over_seeds(g)
            is_ref = (name, scheme, y, tol, order) == ref_key
            err = 0.0 if is_ref else m - ref_m
            bar = e if is_ref else math.hypot(e, ref_e)
            ov = max(r["max_overlap_over_radius"] for r in g)
            w.writerow([scheme, g[0]["youngs_modulus"], tol or "", order or "", len(g), m, e, sec, err, bar, ov])
            points.append((scheme, g[0]["youngs_modulus"], tol, order, m, e, sec, err, bar, is_ref))
            print(f"{name:32s}: {m:.1f} +- {e:.1f} Pa, {sec:.2f} s per strain, error {err:+.1f} +- {bar:.1f}"
                  f" Pa ({err / bar if bar else 0:+.2f} sigma), max overlap/R {ov:.3g}")
    ratios = [a["wall_seconds"] / b["wall_seconds"] for a, b in timing]
    print("timing, one strain unit at 200 GPa, side by side: " +
          ", ".join(f"verlet_exp {a['wall_seconds']:.2f} s / implicit {b['wall_seconds']:.2f} s = {a['wall_seconds'] / b['wall_seconds']:.2f}"
                    for a, b in timing) + f"; median ratio {sorted(ratios)[1]:.2f}")

    fig, ax = plt.subplots(figsize=(5.4, 4.0), dpi=110)
    styles = {"verlet_exp": ("o", "tab:blue"), "implicit": ("s", "tab:red")}
    floor = 3.0
    for scheme, y, tol, order, m, e, sec, err, bar, is_ref in points:
        mk, c = styles[scheme]
        if order == "1":
            mk, c = "^", "tab:green"
        if is_ref:
            ax.axvline(sec, color=c, ls="--", lw=1)
            ax.annotate("reference: explicit 200 GPa", (sec, floor * 1.2), fontsize=7, rotation=90, ha="right")
            continue
        yv = max(abs(err), floor)
        ax.errorbar(sec, yv, yerr=[[min(bar, yv - 1.0)], [bar]], fmt=mk, color=c,
                    mfc=c if y >= 1e11 else "white", capsize=2)
        text = f"{y / 1e9:g} GPa" if scheme == "verlet_exp" or tol == "0.01" and y < 1e11 else \
            f"tol {tol}" + (" (low)" if err < 0 else "")
        ax.annotate(text, (sec, yv), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.errorbar([], [], fmt="o", color="tab:blue", mfc="white", label="explicit verlet_exp, soft Y")
    ax.errorbar([], [], fmt="s", color="tab:red", mfc="white", label="implicit, soft Y")
    ax.errorbar([], [], fmt="s", color="tab:red", label="implicit BDF2, Y = 200 GPa (implicit_tol)")
    ax.errorbar([], [], fmt="^", color="tab:green", label="implicit order 1, Y = 200 GPa")
    ax.axhline(ref_e, color="gray", ls=":", lw=1, label="reference error bar")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per strain unit (s, 1 thread)")
    ax.set_ylabel("|stress_total - reference| (Pa)")
    ax.set_title(f"small scene, Mn = 1e-2, {len(seeds)} seeds, strain {warm}-{strain}; "
                 f"reference {ref_m:.0f} ± {ref_e:.0f} Pa", fontsize=8)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "implicit_small_scene.png"))
    print("wrote", path_csv)


if __name__ == "__main__":
    main()
