#!/usr/bin/python3
"""The paper-scale report while its steadiness re-runs are still running.

experiments/sweeps/paper_realistic.toml holds re-run rules (strain and
warm-up doubled) for the points whose first run failed a steadiness test.
Until a re-run has finished, its point's archive entry is the first run,
which the full sweep file calls stale. This builds a temporary sweep file
with only the re-run rules whose points have all finished at the rule's
strain (the others' points then read as their first runs), collects it from
the archive, runs `mrf criterion`, copies sweep.csv and criterion.json into
reports/study/paper/ and writes the report with --note NOTE. The fixed-M
path's tables are refreshed from reports/study/paper/fixed_m_points the same
way (a point whose re-run is pending reads as its first run there too), and
so is the convergence table (reports/study/paper/convergence.md) from
reports/study/paper/convergence/points. Model 1 takes the extra seeds of
experiments/sweeps/paper_mn01_states.toml (Mn 0.1) and
paper_model1_seeds.toml (the other Mn) into its headline points,
and reports/paper_model1_seeds.py shows every seed's window (and, beside
model 3's point at Mn 0.1, never in it, the long runs of
paper_mn01_long.toml by the reading fixed there)
(reports/study/paper/model1_seeds.md); model 3 at Mn 0.1 takes those of
paper_mn01_coupled_seeds.toml. An extra-seed sweep's own re-runs for
steadiness (session 40) are read as the headline's: a point whose re-run
is pending reads as its first run. The coupled points at Mn 1e-3 become
the common-reference runs of paper_common_low.toml once all six are in
(carrier_swap; reports/study/paper/low_carrier.csv holds both carriers'
runs there), while the convergence table keeps the per-particle headline
as its base. reports/paper_tolerance.py applies
the rules of experiments/sweeps/paper_tolerance.toml,
paper_tolerance_coupled.toml and experiments/branch_tolerance.txt to their
runs (reports/study/paper/tolerance.md).

With --runs the eleven sweeps are read from their run folders
(out/sweeps/<sweep name>, laid out as an archive is) instead of the
committed archives: what `scripts/reproduce paper` does after running them
from scratch.

usage: scripts/paper_interim.py [--mrf build/mrf] [--note TEXT] [--runs]
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GRID = [1e-3, 1e-2, 0.1, 1.0, 10.0]


def arg(key, default):
    return sys.argv[sys.argv.index(key) + 1] if key in sys.argv else default


def interim_toml(src_path, archive, out_path):
    src = open(src_path).read()
    head, *rules = src.split("[[rule]]")
    rerun_start = src.index("# Re-runs for steadiness")
    keep, pos, pending = [], len(head), {}
    # a rule without seeds covers every seed of the sweep
    head_seeds = [int(x) for x in re.search(r"seeds\s*=\s*\[(.*?)\]", head).group(1).split(",")]
    for r in rules:
        start = pos
        pos += len("[[rule]]") + len(r)
        if start < rerun_start:  # the strain rules of the design, not re-runs
            keep.append(r)
            continue
        # a re-run rule names its models, Mn range and seeds (paper_realistic.toml's form)
        models = re.findall(r'"(\w+)"', re.search(r"models\s*=\s*\[(.*?)\]", r).group(1))
        lo = float(re.search(r"mason_min\s*=\s*([\d.e+-]+)", r).group(1))
        hi = float(re.search(r"mason_max\s*=\s*([\d.e+-]+)", r).group(1))
        sd_text = re.search(r"seeds\s*=\s*\[(.*?)\]", r)
        seeds = [int(x) for x in sd_text.group(1).split(",")] if sd_text else head_seeds
        var_text = re.search(r"variants\s*=\s*\[(.*?)\]", r)
        variants = re.findall(r'"([\w.-]+)"', var_text.group(1)) if var_text else [""]
        sets = re.search(r"^set\s*=\s*\[(.*?)\]", r, re.S | re.M).group(1).strip()
        strain = float(re.search(r"drive\.strain=([\d.]+)", r).group(1))
        # one rule per point whose re-run has finished (the others read as their first runs)
        for m in models:
            for v in variants:
                for mn in [g for g in GRID if lo <= g <= hi]:
                    for sd in seeds:
                        f = os.path.join(archive, m, v, f"mn_{mn:g}_seed_{sd}", "summary.json")
                        key = (m, v, mn, sd)
                        if os.path.exists(f) and json.load(open(f))["strain"] == strain:
                            keep.append(("\nvariants = [\"" + v + "\"]" if v else "")
                                        + f'\nmodels = ["{m}"]\nmason_min = {mn!r}\nmason_max = {mn!r}\n'
                                        f'seeds = [{sd}]\nset = [{sets}]\n\n')
                            pending.pop(key, None)  # a later rule's run has finished: the earlier one's is moot
                        else:
                            pending[key] = f"{m} {v + ' ' if v else ''}Mn {mn:g} seed {sd}"
    with open(out_path, "w") as fh:
        fh.write(head + "".join("[[rule]]" + r for r in keep))
    return list(pending.values())


def collect(mrf, toml, archive, out):
    """`mrf sweep TOML --collect` from `archive` into a clean `out` (the
    archive is the record). A sweep file with re-runs for steadiness is read
    through interim_toml: a point whose re-run is pending reads as its first
    run (the pending ones are printed)."""
    shutil.rmtree(out, ignore_errors=True)
    name = os.path.basename(toml)[:-len(".toml")]
    tmp, src = os.path.join(os.path.dirname(toml), f"_{name}_interim.toml"), toml  # beside it: the scene path is relative
    try:
        if "# Re-runs for steadiness" in open(toml).read():
            pending = interim_toml(toml, archive, tmp)
            print(f"{name}: re-runs pending: {', '.join(pending) if pending else 'none'}")
            src = tmp
        subprocess.run([mrf, "sweep", src, "--out", out, "--archive", archive, "--collect", "--quiet"], check=True)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


# Extra-seed sweeps of the headline (model 1, seeds 4-8; model 3 at Mn 0.1,
# seeds 4-6; each fixed in advance): sweep name and committed archive.
EXTRA_SEEDS = [("paper_mn01_states", "mn01_states/points"), ("paper_model1_seeds", "model1_seeds/points"),
               ("paper_mn01_coupled_seeds", "mn01_coupled_seeds/points")]


def merge_extra_seeds(mrf, toml, archive, out):
    """Appends the finished runs of an extra-seed sweep (EXTRA_SEEDS) to the
    collected sweep in `out` (its `mrf criterion` is to be run again after,
    so that the points' means and error bars take every seed). Returns the
    number of runs merged."""
    if not os.path.isdir(archive):
        return 0
    extra = out + "_" + os.path.basename(toml)[:-len(".toml")]
    collect(mrf, toml, archive, extra)  # its re-runs for steadiness (session 40) read as the headline's
    rows = open(os.path.join(extra, "sweep.csv")).read().splitlines()[1:]
    with open(os.path.join(out, "sweep.csv"), "a") as fh:
        fh.writelines(line + "\n" for line in rows)
    return len(rows)


def carrier_rows(head, common, n_design):
    """The headline's rows and low_carrier.csv's (see carrier_swap) from the
    collected headline `head` and the finished common-reference runs
    `common` (rows as dicts), of a design of n_design runs: (headline,
    table, swapped?). The headline takes the common runs in place of its
    coupled rows at Mn 1e-3 only once all n_design are in."""
    low = lambda r: r["model"] in ("demsph_stokes", "demsph_dd") and abs(float(r["mason"]) - 1e-3) < 1e-9  # noqa: E731
    swap = len(common) == n_design
    table = ([dict(r, carrier="per_particle", in_headline="no" if swap else "yes") for r in head if low(r)]
             + [dict(r, carrier="common", in_headline="yes" if swap else "no") for r in common])
    return ([r for r in head if not low(r)] + common if swap else head), table, swap


def carrier_swap(mrf, toml, archive, out, table):
    """The coupled points at Mn 1e-3 under the common EOS reference
    (experiments/sweeps/paper_common_low.toml, the re-runs that
    paper_convergence.toml's session-39 rule called for). Collects the
    sweep from `archive`; once every point of its design has finished, the
    collected headline in `out` (sweep.csv) takes these runs in place of
    its coupled rows at Mn 1e-3 (its `mrf criterion` is to be run after).
    Writes `table`: the coupled rows at Mn 1e-3 of both carriers, with
    columns carrier (per_particle, common) and in_headline (yes, no).
    Returns (finished runs, runs of the design, swapped?)."""
    head_path = os.path.join(out, "sweep.csv")
    reader = csv.DictReader(open(head_path))
    header, head = reader.fieldnames, list(reader)
    common = []
    if os.path.isdir(archive):
        collect(mrf, toml, archive, out + "_paper_common_low")
        common = [r for r in csv.DictReader(open(os.path.join(out + "_paper_common_low", "sweep.csv")))
                  if r["status"] == "ok"]
    design = tomllib.load(open(toml, "rb"))["sweep"]
    n_design = len(design["models"]) * len(design["mason"]) * len(design["seeds"])
    head, rows, swap = carrier_rows(head, common, n_design)
    for path, cols, data in ((head_path, header, head), (table, header + ["carrier", "in_headline"], rows)):
        with open(path, "w", newline="") as fh:
            w = csv.DictWriter(fh, cols, lineterminator="\n")
            w.writeheader()
            w.writerows(data)
    return len(common), n_design, swap


def reanalysed(mrf, archive, out_path):
    """`mrf reanalyse` on every archive entry that keeps its window series
    (window_series.csv), one record per run with its model, Mn and seed:
    the version-2 estimate of runs whose summaries carry the plain one, for
    the report's post-hoc reading of the particle-part rule."""
    records = []
    for dirpath, _, files in sorted(os.walk(archive)):
        if "window_series.csv" not in files or "summary.json" not in files:
            continue
        s = json.load(open(os.path.join(dirpath, "summary.json")))
        r = json.loads(subprocess.run([mrf, "reanalyse", dirpath], check=True, capture_output=True, text=True).stdout)
        r.update(model=s["model"], mason=s["mason"], seed=s["seed"], strain=s["strain"])
        records.append(r)
    with open(out_path, "w") as fh:
        json.dump(records, fh, indent=1)
        fh.write("\n")
    return len(records)


def main():
    os.chdir(ROOT)
    mrf = arg("--mrf", "build/mrf")
    paper = "reports/study/paper"
    sweeps = "experiments/sweeps"
    per_particle = os.path.join("out", "sweeps", "paper_realistic_interim_per_particle.csv")
    # where each sweep's finished points are read from
    if "--runs" in sys.argv:
        names = ["paper_realistic", "paper_fixed_m", "paper_low_mn", "paper_convergence", "paper_common_low"] + [
            n for n, _ in EXTRA_SEEDS]
        src = {n: os.path.join("out", "sweeps", n) for n in names}
    else:
        src = {"paper_realistic": f"{paper}/points", "paper_fixed_m": f"{paper}/fixed_m_points",
               "paper_low_mn": f"{paper}/low_mn_points", "paper_convergence": f"{paper}/convergence/points",
               "paper_common_low": f"{paper}/common_low/points"}
        src.update({n: f"{paper}/{a}" for n, a in EXTRA_SEEDS})
    for name, archive, csv_name, crit_name in (
            ("paper_realistic", src["paper_realistic"], "sweep.csv", "criterion.json"),
            ("paper_fixed_m", src["paper_fixed_m"], "fixed_m_sweep.csv", "fixed_m_criterion.json")):
        out = os.path.join("out", "sweeps", name + "_interim")
        collect(mrf, os.path.join(sweeps, name + ".toml"), archive, out)
        if name == "paper_realistic":
            for extra, _ in EXTRA_SEEDS:
                n = merge_extra_seeds(mrf, os.path.join(sweeps, extra + ".toml"), src[extra], out)
                print(f"{extra}: {n} runs merged into the headline points")
            # the convergence table's base stays the per-particle carrier (its rows are variants of it)
            shutil.copy(os.path.join(out, "sweep.csv"), per_particle)
            done, n, swap = carrier_swap(mrf, os.path.join(sweeps, "paper_common_low.toml"), src["paper_common_low"],
                                         out, os.path.join(paper, "low_carrier.csv"))
            print(f"paper_common_low: {done} of {n} runs finished; the coupled points at Mn 1e-3 are "
                  + ("the common reference's" if swap else "the per-particle carrier's until all are in"))
        subprocess.run([mrf, "criterion", out], check=True, stdout=subprocess.DEVNULL)
        shutil.copy(os.path.join(out, "sweep.csv"), os.path.join(paper, csv_name))
        shutil.copy(os.path.join(out, "criterion.json"), os.path.join(paper, crit_name))
    n = reanalysed(mrf, src["paper_realistic"], os.path.join(paper, "reanalysed.json"))
    print(f"paper_realistic: {n} runs re-analysed from their window series (runs that carry the version-2 "
          "estimate need none; a run folder keeps no window series)")
    # model 1 below Mn 1e-3 (no re-run rules: collected as it stands)
    if os.path.isdir(src["paper_low_mn"]):
        out = os.path.join("out", "sweeps", "paper_low_mn_interim")
        collect(mrf, os.path.join(sweeps, "paper_low_mn.toml"), src["paper_low_mn"], out)
        shutil.copy(os.path.join(out, "sweep.csv"), os.path.join(paper, "low_mn_sweep.csv"))
    # model 1's long windows at Mn 3e-4 and 1e-3 (paper_model1_low_long.toml): its own sweep.csv
    if "--runs" in sys.argv:
        low_long = os.path.join("out", "sweeps", "paper_model1_low_long")
    else:
        low_long = f"{paper}/model1_low_long/points"
    if os.path.isdir(low_long):
        out = os.path.join("out", "sweeps", "paper_model1_low_long_interim")
        collect(mrf, os.path.join(sweeps, "paper_model1_low_long.toml"), low_long, out)
        shutil.copy(os.path.join(out, "sweep.csv"), os.path.join(paper, "model1_low_long", "sweep.csv"))
    # the convergence variants against the realistic path's seed means
    out = os.path.join("out", "sweeps", "paper_convergence_interim")
    collect(mrf, os.path.join(sweeps, "paper_convergence.toml"), src["paper_convergence"], out)
    subprocess.run(["/usr/bin/python3", "reports/paper_convergence.py", os.path.join(out, "sweep.csv"),
                    per_particle, os.path.join(paper, "convergence.md")], check=True)
    cmd = ["/usr/bin/python3", "reports/paper_study.py", "out/sweeps/paper_realistic_interim", paper,
           "--points", src["paper_realistic"], "--common-points", src["paper_common_low"]]
    if "--note" in sys.argv:
        cmd += ["--note", arg("--note", "")]
    subprocess.run(cmd, check=True)
    runs = ["--runs"] if "--runs" in sys.argv else []
    subprocess.run(["/usr/bin/python3", "reports/paper_model1_seeds.py", paper] + runs, check=True)
    subprocess.run(["/usr/bin/python3", "reports/paper_tolerance.py", paper] + runs, check=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
