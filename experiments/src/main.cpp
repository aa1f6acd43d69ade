// The `mrf` command line (DESIGN.md §Interfaces).
//   mrf run SCENE.toml [--set section.key=value]... [--out DIR] [--quiet] [--resume] [--checkpoint-every S]
//           [--branch-from STATE] [--keep-final-state]
//   mrf criterion SWEEP_DIR|RUN_DIR [--thresholds FILE]
//   mrf quasistatic SCENE.toml [--set k=v]... [--out DIR] [--increment D] [--tol T] [--strain S] [--warmup W]
//             [--cutoff R] [--no-affine] [--minimiser fire|lbfgs] [--lbfgs-memory M] [--resume]
//             [--branch-from CHECKPOINT] [--start-from FRAMES] [--checkpoint-every S]
//   mrf sweep SWEEP.toml [--out DIR] [--quiet] [--estimate | --list | --collect] [--point K | --rank R --ranks K]
//             [--checkpoint-every S] [--archive DIR] [--calibrate-from DIR]   (mpirun -n K: master-worker schedule)
// Exit status: 0 done, 2 bad input, 3 numerical failure or refused
// checkpoint, 4 a sweep point failed, 5 output could not be written, 1 other.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "criterion_command.hpp"
#include "quasistatic_command.hpp"
#include "mrf/error.hpp"
#include "mrf/io/lammps_data.hpp"
#include "mrf/io/timeseries.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/study/point_claim.hpp"
#include "mrf/study/sweep.hpp"
#include "mrf/version.hpp"

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

int run_command(const std::string& scene_path, const std::vector<std::string>& sets, std::string out, bool quiet,
                mrf::RunOptions opt) {
  const mrf::LoadedScene scene = mrf::load_scene(scene_path, sets);
  if (out.empty()) out = "out/" + std::filesystem::path(scene_path).stem().string();
  opt.out_dir = out;
  opt.quiet = quiet;
  const mrf::RunSummary s = mrf::run_scene(scene, opt);
  std::printf("%s Mn=%.4g: stress_total = %.6g +- %.2g Pa (particles %.6g, fluid %.6g, virial %.6g +- %.2g), "
              "drift z = %.2f; %ld steps, %.1f s -> %s/summary.json\n",
              s.model.c_str(), s.mason, s.stress_total.mean, s.stress_total.err,
              s.stress_particles.mean, s.stress_fluid, s.stress_virial.mean, s.stress_virial.err,
              s.stress_total.drift_z, s.steps, s.wall_seconds, out.c_str());
  return 0;
}

int export_lammps(const std::string& scene_path, const std::vector<std::string>& sets,
                  const std::string& out) {
  const mrf::LoadedScene scene = mrf::load_scene(scene_path, sets);
  const mrf::DemParams p = mrf::dem_params(scene.config);
  const mrf::TimeStepChoice ts = mrf::choose_time_step(scene, p);
  const mrf::ShearCell cell = mrf::build_shear_cell(scene.config, scene.locate("particles.volume_fraction"));
  mrf::write_lammps_data(cell, p, out + ".data");
  mrf::write_lammps_params(p, cell.box, ts.dt, out + ".params");
  std::printf("wrote %s.data (%zu free + %zu wall spheres) and %s.params\n", out.c_str(),
              cell.free.size(), cell.walls.size(), out.c_str());
  return 0;
}

#ifdef MRF_HAVE_MPI
}  // namespace
int mpi_sweep(const mrf::SweepSpec& spec, const std::string& out, const mrf::SweepOptions& opt,
              const std::vector<std::string>& point_command);  // mpi/mpi_sweep.cpp
namespace {
#endif

struct SweepArgs {
  std::string file, out, archive;
  std::vector<std::string> calibrate;
  bool quiet = false, estimate = false, list = false, collect = false, no_csv = false;
  int rank = 0, ranks = 0;
  long point = -1;
  double checkpoint_seconds = 60;
};

int sweep_command(const SweepArgs& a) {
  std::string out = a.out;
  const mrf::SweepSpec spec = mrf::load_sweep(a.file);
  if (out.empty()) out = "out/sweeps/" + std::filesystem::path(a.file).stem().string();
  mrf::SweepOptions opt;
  opt.quiet = a.quiet;
  opt.rank = mrf::rank_from_environment();
  if (a.ranks > 0) {
    if (a.rank < 0 || a.rank >= a.ranks)
      throw mrf::InputError("--rank", std::to_string(a.rank), "", "must be in [0, --ranks)");
    opt.rank = {a.rank, a.ranks};
  }
  if (a.point >= 0 && a.ranks > 0)
    throw mrf::InputError("--point", std::to_string(a.point), "", "runs one point; leave out --rank/--ranks");
  opt.point = a.point;
  if (!(a.checkpoint_seconds >= 0))
    throw mrf::InputError("--checkpoint-every", std::to_string(a.checkpoint_seconds), "", "must be >= 0 (0 = none)");
  opt.checkpoint_seconds = a.checkpoint_seconds;
  opt.archive = a.archive;
  opt.calibrate = a.calibrate;
  for (const std::string& d : a.calibrate)
    if (!std::filesystem::is_directory(d))
      throw mrf::InputError("--calibrate-from", d, "", "is not a folder (of finished points' summary.json)");
  opt.write_csv = !a.no_csv;
  // --collect reads --out, so it first makes it what a run would find: a
  // folder of another scene set aside (never a running point's: both under
  // the point's claim) and the archive restored into it (a run does this for
  // its own share, run_sweep); --list and --estimate write nothing and read
  // the archive where it is
  if (!a.archive.empty() && a.collect) {
    mrf::set_aside_stale(spec, mrf::sweep_points(spec), out, a.quiet);
    mrf::report_archive(mrf::restore_from_archive(spec, mrf::sweep_points(spec), out, a.archive), a.archive, a.quiet);
  }
  if (a.collect) {  // sweep.csv from the finished points, nothing run (while other ranks still work)
    const auto points = mrf::sweep_points(spec);
    const std::size_t done = mrf::write_sweep_csv(points, out, &spec);
    std::printf("%zu of %zu points finished -> %s/sweep.csv\n", done, points.size(), out.c_str());
    return 0;
  }
  if (a.list) {
    // index, folder, state and estimate of every point: what a job array or
    // GNU parallel needs to hand `--point K` out
    const auto points = mrf::sweep_points(spec);
    const mrf::PointEstimates est = mrf::estimate_points(spec, points, out, opt.cost_rate, a.archive, a.calibrate);
    std::printf("%-5s %-40s %-14s %-9s %-5s %-9s %s\n", "point", "folder", "model", "Mn", "seed", "state",
                "estimate (s; * = from the particle-steps model, no point of the model finished)");
    for (const auto& p : points) {
      const std::filesystem::path dir = std::filesystem::path(out) / p.dir;
      // as a run would find it: a folder for another scene is set aside and
      // a current archive entry restored (the point then does not run)
      const bool stale_here = mrf::point_stale(spec, p, dir);
      const bool archived_entry =
          !a.archive.empty() && std::filesystem::exists(std::filesystem::path(a.archive) / p.dir / "summary.json");
      const char* state = !stale_here && std::filesystem::exists(dir / "summary.json") ? "finished"
                          : mrf::archive_entry_current(spec, p, a.archive)              ? "archived"
                          : stale_here                                                   ? "stale"
                          : std::filesystem::exists(dir / "failure.json")               ? "failed"
                          : !mrf::point_claim_holder(dir).empty()                        ? "running"
                          : std::filesystem::exists(dir / "checkpoint.bin")             ? "started"
                          : archived_entry                                               ? "stale"
                                                                                         : "todo";
      std::string progress;  // a run under way: the strain of its last series row
      if (std::string_view(state) == "started" || std::string_view(state) == "running") {
        const double strain = mrf::load_scene(spec.scene_path, p.sets).config.strain;
        char buf[96];
        std::snprintf(buf, sizeof buf, "  (strain %.3g of %.3g)", mrf::point_strain_reached(dir.string()), strain);
        progress = buf;
      }
      std::printf("%-5zu %-40s %-14s %-9g %-5llu %-9s %.3g%s%s\n", p.index, p.dir.c_str(), p.model.c_str(), p.mason,
                  static_cast<unsigned long long>(p.seed), state, est.seconds[p.index],
                  est.calibrated[p.index] ? "" : " *", progress.c_str());
    }
    return 0;
  }
  if (a.estimate) {
    const auto points = mrf::sweep_points(spec);
    const mrf::PointEstimates est = mrf::estimate_points(spec, points, out, opt.cost_rate, a.archive, a.calibrate);
    double total = 0, left = 0;
    std::size_t model_only = 0, to_run = 0;
    for (const auto& p : points) {
      const double e = est.seconds[p.index];
      // done: a summary of this scene in --out or the archive (finished), or
      // a failure.json in --out (failed: a sweep does not run it again)
      auto has = [&](const std::string& root, const char* file) {
        const std::filesystem::path dir = std::filesystem::path(root) / p.dir;
        return !root.empty() && std::filesystem::exists(dir / file) && !mrf::point_stale(spec, p, dir);
      };
      const bool finished = has(out, "summary.json") || mrf::archive_entry_current(spec, p, a.archive);
      const bool failed = !finished && has(out, "failure.json");
      // a run under way (a checkpoint and series rows in --out) has only the rest of its strain to go
      const double share = finished || failed ? 1.0 : mrf::point_fraction_left(spec, p, out);
      char started[96] = "";
      if (share < 1.0)
        std::snprintf(started, sizeof started, " (started: strain %.3g of %.3g, %.3g s left)",
                      mrf::point_strain_reached((std::filesystem::path(out) / p.dir).string()),
                      mrf::load_scene(spec.scene_path, p.sets).config.strain, e * share);
      std::printf("%-40s estimated %.3g s%s%s%s\n", p.dir.c_str(), e, est.calibrated[p.index] ? "" : " *",
                  finished ? " (finished)" : failed ? " (failed)" : "", started);
      if (e == e) total += e;
      if (!finished && !failed) {
        ++to_run;
        if (e == e) left += e * share;
      }
      model_only += est.calibrated[p.index] ? 0 : 1;
    }
    // the last two lines: what is left to run, then the whole sweep
    std::printf("to run %.3g s (%.3g h) on one core: %zu of %zu points (%zu finished or failed in %s%s)\n", left,
                left / 3600, to_run, points.size(), points.size() - to_run, out.c_str(),
                a.archive.empty() ? "" : (" or " + a.archive).c_str());
    std::printf("total %.3g s (%.3g h) on one core; %zu points (*) from the particle-steps model at %.3g "
                "particle-steps/s (blind to the implicit schemes' error-controlled steps: a lower bound), the rest "
                "from the finished points in %s%s%s\n",
                total, total / 3600, model_only, opt.cost_rate, out.c_str(),
                a.archive.empty() ? "" : (" and " + a.archive).c_str(),
                a.calibrate.empty() ? "" : (" and, for the cost alone, " + join(a.calibrate)).c_str());
    return 0;
  }
#ifdef MRF_HAVE_MPI
  // under mpirun (more than one rank, no explicit share): the master-worker schedule
  if (opt.rank.size > 1 && a.ranks == 0 && a.point < 0) {
    // a worker runs each point as `mrf sweep FILE --point J` in a child process, so that a point that dies
    // (OOM killer, a crash) is reported and the sweep goes on
    std::vector<std::string> cmd{"mrf", "sweep", a.file, "--out", out, "--quiet", "--no-csv", "--checkpoint-every",
                                 std::to_string(a.checkpoint_seconds)};
    if (!a.archive.empty()) cmd.insert(cmd.end(), {"--archive", a.archive});
    return mpi_sweep(spec, out, opt, cmd);
  }
#endif
  const mrf::SweepOutcome o = mrf::run_sweep(spec, out, opt);
  const std::string who = a.point >= 0 ? "point " + std::to_string(a.point)
                                       : "rank " + std::to_string(opt.rank.rank) + "/" + std::to_string(opt.rank.size);
  std::printf("sweep %s %s: %zu run, %zu skipped (finished before), %zu failed, %zu left to other processes, %zu with "
              "a refused checkpoint, %.1f s -> %s/sweep.csv\n",
              a.file.c_str(), who.c_str(), o.ran, o.skipped, o.failed, o.elsewhere, o.refused, o.seconds, out.c_str());
  return o.failed > 0 ? 4 : o.refused > 0 ? 3 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mrf: magnetorheological fluid in a shear cell (DEM, DEM-SPH)"};
  app.set_version_flag("--version", std::string("mrf ") + mrf::version() + " (git " + mrf::git_revision() + ")");
  app.require_subcommand(1);
  auto* run = app.add_subcommand("run", "run one scene and write summary.json and timeseries.csv");
  std::string scene, out;
  std::vector<std::string> sets;
  bool quiet = false;
  run->add_option("scene", scene, "scene file (TOML)")->required();
  run->add_option("--set", sets, "override one key: section.key=value (repeatable)");
  run->add_option("--out", out, "output directory (default out/<scene name>)");
  run->add_flag("--quiet", quiet, "no start-up table or progress on stderr");
  mrf::RunOptions run_opt;
  run->add_flag("--resume", run_opt.resume, "continue from OUT/checkpoint.bin if it exists (same scene and overrides)");
  run->add_option("--checkpoint-every", run_opt.checkpoint_seconds, "wall seconds between checkpoints (0 = none)")
      ->capture_default_str();
  run->add_option("--branch-from", run_opt.branch_from,
                  "start from this state of another run (its checkpoint.bin or final_state.bin) unless OUT holds a "
                  "checkpoint to resume; the scene may differ from the parent's only in numerical keys (a refused "
                  "key is named; docs/study.md, Branches)")
      ->check(CLI::ExistingFile);
  run->add_flag("--keep-final-state", run_opt.keep_final_state,
                "write OUT/final_state.bin at the end (for --branch-from)");
  auto* exp = app.add_subcommand("export-lammps", "write the scene's initial configuration as a LAMMPS data file");
  std::string exp_scene, exp_out;
  std::vector<std::string> exp_sets;
  exp->add_option("scene", exp_scene, "scene file (TOML)")->required();
  exp->add_option("--set", exp_sets, "override one key: section.key=value (repeatable)");
  exp->add_option("--out", exp_out, "output prefix: writes PREFIX.data and PREFIX.params")->required();
  auto* sw = app.add_subcommand("sweep", "run a grid of models x Mason numbers x seeds; finished points are skipped");
  SweepArgs sa;
  sw->add_option("sweep", sa.file, "sweep file (TOML)")->required();
  sw->add_option("--out", sa.out, "output directory (default out/sweeps/<sweep name>)");
  sw->add_flag("--quiet", sa.quiet, "no progress on stderr");
  sw->add_flag("--estimate", sa.estimate, "print the estimated cost of every point and stop");
  sw->add_flag("--list", sa.list, "print every point: index, folder, model, Mn, seed, state in --out, estimate; stop");
  sw->add_flag("--collect", sa.collect, "write sweep.csv from the finished points in --out and stop (runs nothing)");
  sw->add_option("--archive", sa.archive,
                 "folder of finished points' summary.json (committed): restored into --out first, added to as points "
                 "finish; an entry of an edited scene is ignored");
  sw->add_option("--calibrate-from", sa.calibrate,
                 "folder laid out like an archive whose summaries calibrate the cost estimates only (nothing is "
                 "restored from it): an estimate for a fresh run from the measured cost of an earlier one; "
                 "repeatable, the first folder that has a point calibrates it");
  sw->add_flag("--no-csv", sa.no_csv, "do not rewrite sweep.csv at the end (concurrent --point runs: --collect once)");
  sw->add_option("--point", sa.point, "run point K of the grid alone (0-based, as --list numbers them)")
      ->check(CLI::Validator(
          [](const std::string& v) {
            return !v.empty() && v[0] != '-' ? std::string() : "must be 0 or more (mrf sweep FILE --list numbers them)";
          },
          "K >= 0"));
  sw->add_option("--checkpoint-every", sa.checkpoint_seconds, "wall seconds between a point's checkpoints (0 = none)")
      ->capture_default_str();
  auto* ranks = sw->add_option("--ranks", sa.ranks, "number of shares the grid is split into (round-robin)");
  sw->add_option("--rank", sa.rank, "run the share of rank R (0-based) of --ranks K; default: from mpirun, else all")
      ->needs(ranks);
  auto* cr = app.add_subcommand("criterion", "flow-curve fits, deviation from model 3 and the model-1 verdict");
  std::string cr_path, cr_thresholds;
  cr->add_option("path", cr_path, "a sweep output directory (sweep.csv) or a dem_stokes run directory (summary.json)")
      ->required();
  cr->add_option("--thresholds", cr_thresholds,
                 "JSON with share_10 and share_20 (e.g. experiments/criterion_thresholds.json) for verdicts");
  auto* qs = app.add_subcommand("quasistatic", "athermal quasi-static shear: the Mn -> 0 limit, stress at energy minima");
  std::string qs_scene, qs_out;
  std::vector<std::string> qs_sets;
  mrf::QuasistaticOptions qo;
  QuasistaticCliOptions qs_cli;
  bool no_affine = false;
  double qs_strain = 0, qs_warmup = -1;
  qs->add_option("scene", qs_scene, "scene file (TOML)")->required();
  qs->add_option("--set", qs_sets, "override one key: section.key=value (repeatable)");
  qs->add_option("--out", qs_out, "output directory (default out/<scene name>_quasistatic)");
  qs->add_option("--increment", qo.strain_increment, "strain increment per minimisation")->capture_default_str();
  qs->add_option("--tol", qo.force_tol, "accepted minimum: max |f| < tol F0")->capture_default_str();
  qs->add_option("--strain", qs_strain, "total strain (default the scene's drive.strain)");
  qs->add_option("--warmup", qs_warmup, "strain left out of the steady mean (default drive.warmup_strain)");
  qs->add_option("--cutoff", qo.dipole_cutoff, "shifted-force dipole cut-off in m (default particles.dipole_cutoff)");
  std::string qs_minimiser = "fire";
  qs->add_option("--minimiser", qs_minimiser, "energy minimiser: fire (FIRE 2.0), lbfgs (L-BFGS) or descent (steepest descent, the gradient flow)")
      ->capture_default_str();
  qs->add_option("--lbfgs-memory", qo.lbfgs_memory, "L-BFGS correction pairs")->capture_default_str();
  qs->add_option("--descent-step", qo.descent_step_times_k,
                 "steepest descent: Euler step of the gradient flow times the contact stiffness k_eff")
      ->capture_default_str();
  qs->add_option("--max-iterations", qo.max_iterations, "force evaluations per minimisation after the first")
      ->capture_default_str();
  qs->add_flag("--no-affine", no_affine, "free particles not displaced affinely before each minimisation");
  qs->add_flag("--quiet", qs_cli.quiet, "no progress on stderr");
  qs->add_option("--branch-from", qs_cli.branch_from,
                 "start from another run's checkpoint.bin (same scene and settings but --tol, --minimiser, --increment): a "
                 "pathwise test of any of them from one minimum");
  qs->add_option("--start-from", qs_cli.start_from,
                 "relax the first minimum from the last frame of a frames.xyz of `mrf run` on the same scene "
                 "(output.frames > 0): a structure made by flow instead of the random packing");
  qs->add_flag("--resume", qs_cli.resume,
               "continue from OUT/checkpoint.bin (same scene and options; a larger --strain extends a finished run)");
  qs->add_option("--checkpoint-every", qs_cli.checkpoint_seconds,
                 "wall seconds between checkpoints and partial CSVs (0 = only at the end)")
      ->capture_default_str();
  auto* ra = app.add_subcommand("reanalyse",
                                "a finished run's statistics (wall stress, pair virial) re-estimated from its "
                                "timeseries.csv (or a sweep archive entry's window_series.csv) by this version's block "
                                "averaging, beside what its summary.json holds");
  std::vector<std::string> ra_dirs;
  ra->add_option("dirs", ra_dirs, "run directories (summary.json + timeseries.csv)")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    if (*ra) {
      for (const auto& d : ra_dirs) std::printf("%s\n", mrf::reanalyse_run(d).c_str());
      return 0;
    }
    if (*run) return run_command(scene, sets, out, quiet, run_opt);
    if (*exp) return export_lammps(exp_scene, exp_sets, exp_out);
    if (*cr) return criterion_command(cr_path, cr_thresholds);
    if (*sw) return sweep_command(sa);
    if (*qs) {
      qo.affine = !no_affine;
      qo.minimiser = mrf::parse_minimiser(qs_minimiser, "--minimiser");
      if (qs_strain > 0) qo.strain = qs_strain;
      if (qs_warmup >= 0) qo.warmup_strain = qs_warmup;
      return quasistatic_command(qs_scene, qs_sets, qs_out, qo, qs_cli);
    }
  } catch (const mrf::InputError& e) {
    std::fprintf(stderr, "mrf: error: %s\n", e.what());
    return 2;
  } catch (const mrf::OutputError& e) {
    std::fprintf(stderr, "\nmrf: output failed: %s\n", e.what());
    return 5;
  } catch (const mrf::CheckpointError& e) {
    std::fprintf(stderr, "mrf: checkpoint refused: %s\n", e.what());
    return 3;
  } catch (const mrf::NumericalError& e) {
    std::fprintf(stderr, "\nmrf: numerical failure: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {  // I/O and the like: a message, not a terminate()
    std::fprintf(stderr, "mrf: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
