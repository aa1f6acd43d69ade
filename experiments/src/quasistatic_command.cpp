// `mrf quasistatic SCENE`: athermal quasi-static shear of the scene's cell
// (quasistatic/aqs.hpp). Writes OUT/quasistatic.csv (one row per accepted
// minimum) and OUT/summary.json (the steady means of the wall and virial
// stress with their block-average errors, in Pa and in phi mu0 M^2, and the
// options that produced them). The scene's shear rate and Mason number play
// no part: the limit is rate-independent.
//
// A run of the paper cell takes hours: every --checkpoint-every wall seconds
// (and at the end) OUT/checkpoint.bin and the CSV of the minima so far are
// written; --resume continues from the checkpoint, bit for bit, and with a
// larger --strain extends a finished run. The checkpoint names its scene
// (scene_id) and options; another scene or increment, tolerance, affine
// start, cut-off or minimiser is refused. --branch-from CHECKPOINT starts a
// new run (a new --out) from another run's checkpoint at another --tol,
// --minimiser or --increment, everything else the same: both then go on from one minimum,
// a pathwise comparison; OUT/branch.json and summary.json's branched_from say where.
// --start-from FRAMES relaxes the first minimum from the last frame of an
// `mrf run` of the same scene (a structure made by flow) instead of from the
// random packing; summary.json's started_from names the file and the
// frame's time.
#include "quasistatic_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/version.hpp"

namespace {

std::string csv_text(const mrf::QuasistaticResult& r) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "strain,stress_wall,stress_virial,stress_virial_magnetic,stress_virial_contact,energy,max_force,"
         "max_overlap,iterations\n";
  for (std::size_t k = 0; k < r.strain.size(); ++k)
    csv << r.strain[k] << "," << r.stress_wall[k] << "," << r.stress_virial[k] << "," << r.stress_virial_magnetic[k]
        << "," << r.stress_virial_contact[k] << "," << r.energy[k] << "," << r.max_force[k] << "," << r.max_overlap[k]
        << "," << r.iterations[k] << "\n";
  return csv.str();
}

void write_checkpoint(const mrf::QuasistaticRun& run, const std::string& id, const std::string& out) {
  mrf::ArchiveWriter w(out + "/checkpoint.bin");
  w.put(id);
  run.save(w);
  w.close();
  mrf::write_file_atomic(out + "/quasistatic.csv", csv_text(run.series()));
}

}  // namespace

int quasistatic_command(const std::string& scene_path, const std::vector<std::string>& sets, std::string out,
                        const mrf::QuasistaticOptions& options, const QuasistaticCliOptions& cli) {
  const mrf::LoadedScene scene = mrf::load_scene(scene_path, sets);
  if (out.empty()) out = "out/" + std::filesystem::path(scene_path).stem().string() + "_quasistatic";
  if (!(cli.checkpoint_seconds >= 0))
    throw mrf::InputError("--checkpoint-every", std::to_string(cli.checkpoint_seconds), "", "must be >= 0 (0 = none)");
  if (!cli.start_from.empty() && !cli.branch_from.empty())
    throw mrf::InputError("--start-from", cli.start_from, "", "cannot be combined with --branch-from (a branch starts from its checkpoint)");
  mrf::QuasistaticRun run = mrf::quasistatic_run(scene, options, cli.start_from);
  const mrf::QuasistaticOptions& opt = run.options();
  const std::string id = mrf::scene_id(scene.config), ckpt = out + "/checkpoint.bin";
  std::filesystem::create_directories(out);
  const bool resuming = cli.resume && std::filesystem::exists(ckpt);
  if (!cli.branch_from.empty() && !resuming) {
    if (std::filesystem::exists(ckpt))
      throw mrf::InputError("--out", out, "", "holds a checkpoint of an earlier run: a branch starts in a new --out");
    if (!std::filesystem::exists(cli.branch_from))
      throw mrf::InputError("--branch-from", cli.branch_from, "", "no such checkpoint");
    mrf::ArchiveReader in(cli.branch_from);
    std::string saved;
    in.get(saved);
    if (saved != id)
      throw mrf::NumericalError("checkpoint " + cli.branch_from + " is of scene " + saved + ", this scene (with its --set) is " +
                                id + ": a branch takes the same scene and overrides");
    run.load(in, true);
    in.expect_end();
    nlohmann::ordered_json b;  // what summary.json reports of the branch, also after a --resume of it
    b["checkpoint"] = cli.branch_from;
    b["increment"] = run.next_increment();
    b["strain"] = run.series().strain.back() + opt.strain_increment;  // of its first own minimum
    mrf::write_file_atomic(out + "/branch.json", b.dump(2) + "\n");
    if (!cli.quiet)
      std::fprintf(stderr, "mrf quasistatic: branched from %s at increment %zu (minima before it are that run's)\n",
                   cli.branch_from.c_str(), run.next_increment());
  }
  if (resuming) {
    mrf::ArchiveReader in(ckpt);
    std::string saved;
    in.get(saved);
    if (saved != id)
      throw mrf::NumericalError("checkpoint " + ckpt + " is of scene " + saved + ", this scene (with its --set) is " + id +
                                ": resume with the same scene and overrides, or start a new run (another --out)");
    run.load(in);
    in.expect_end();
    if (!cli.quiet)
      std::fprintf(stderr, "mrf quasistatic: resumed from %s at increment %zu of %zu (%.0f s spent)\n", ckpt.c_str(),
                   run.next_increment(), run.increments(), run.wall_seconds());
  } else if (!cli.resume && std::filesystem::exists(ckpt)) {
    throw mrf::InputError("--out", out, "", "holds a checkpoint of an earlier run: --resume continues it, or choose another --out");
  }
  if (!cli.start_from.empty() && !resuming) {
    nlohmann::ordered_json st;  // what summary.json reports of the start, also after a --resume
    st["frames"] = cli.start_from;
    st["time"] = mrf::read_last_frame(cli.start_from, "--start-from").time;
    mrf::write_file_atomic(out + "/start.json", st.dump(2) + "\n");
  } else if (!resuming) {
    std::filesystem::remove(out + "/start.json");  // of an earlier run in this --out
  }
  if (!cli.quiet)
    std::fprintf(stderr, "mrf quasistatic: %s, increments of %g to strain %g, max |f| < %g F0, affine %s, %s\n",
                 scene_path.c_str(), opt.strain_increment, *opt.strain, opt.force_tol, opt.affine ? "on" : "off",
                 mrf::minimiser_name(opt.minimiser));
  const std::size_t first = run.next_increment();
  const double t_first = run.wall_seconds();
  double t_saved = t_first;
  while (!run.done()) {
    const mrf::QuasistaticPoint p = run.step();
    const double t = run.wall_seconds();
    if (!cli.quiet) {
      const double per = (t - t_first) / static_cast<double>(run.next_increment() - first);
      std::fprintf(stderr, "\r  strain %.4f / %g  wall %.4g Pa  virial %.4g Pa  %ld iterations  %.0f s, about %.0f s left   ",
                   p.strain, *opt.strain, p.stress_wall, p.stress_virial, p.iterations, t,
                   per * static_cast<double>(run.increments() + 1 - run.next_increment()));
    }
    if (cli.checkpoint_seconds > 0 && t - t_saved >= cli.checkpoint_seconds && !run.done()) {
      write_checkpoint(run, id, out);
      t_saved = t;
    }
  }
  if (!cli.quiet) std::fprintf(stderr, "\n");
  write_checkpoint(run, id, out);  // kept: --resume with a larger --strain extends the run
  const mrf::QuasistaticResult r = run.finish();
  nlohmann::ordered_json j;
  j["driver"] = std::string("quasistatic (AQS, ") +
                (opt.minimiser == mrf::Minimiser::lbfgs     ? "L-BFGS)"
                 : opt.minimiser == mrf::Minimiser::descent ? "steepest descent)"
                                                            : "FIRE 2.0)");
  j["minimiser"] = mrf::minimiser_name(opt.minimiser);
  if (opt.minimiser == mrf::Minimiser::lbfgs) j["lbfgs_memory"] = opt.lbfgs_memory;
  if (opt.minimiser == mrf::Minimiser::descent) j["descent_step_times_k"] = opt.descent_step_times_k;
  j["scene_id"] = id;
  j["strain_increment"] = opt.strain_increment;
  j["affine"] = opt.affine;
  j["force_tol_over_f0"] = opt.force_tol;
  j["force_tol"] = r.force_tol;
  j["dipole_cutoff"] = r.dipole_cutoff;
  j["minima"] = r.strain.size();
  j["steady_from_strain"] = r.steady_from_strain;
  j["stress_wall"] = r.steady_wall.mean;
  j["stress_wall_err"] = r.steady_wall.sem;
  j["stress_wall_drift_z"] = r.steady_wall.drift_z;
  j["stress_virial"] = r.steady_virial.mean;
  j["stress_virial_err"] = r.steady_virial.sem;
  j["stress_scale"] = r.stress_scale;  // phi mu0 M^2 (Pa)
  j["stress_wall_over_phi_mu0_m2"] = r.steady_wall.mean / r.stress_scale;
  j["stress_wall_over_phi_mu0_m2_err"] = r.steady_wall.sem / r.stress_scale;
  // The periodic orbit (quasistatic/aqs.hpp): when the steady part repeats
  // itself with the walls' period lz/gap, its mean over one period is the
  // value (the block error of a repeating series is not an error bar).
  j["orbit_period_strain"] = r.orbit_period_strain;
  j["orbit_periodic"] = r.orbit_wall.periodic;
  j["orbit_deviation"] = r.orbit_wall.deviation;
  if (r.orbit_wall.period > 0) {
    j["stress_wall_orbit_mean"] = r.orbit_wall.mean;
    j["stress_wall_orbit_mean_over_phi_mu0_m2"] = r.orbit_wall.mean / r.stress_scale;
  }
  j["equilibrium_bound"] = r.equilibrium_bound;
  j["force_evaluations"] = r.force_evaluations;
  j["list_builds"] = r.list_builds;
  j["wall_seconds"] = r.wall_seconds;
  if (std::ifstream branch(out + "/branch.json"); branch)  // minima up to its increment are the parent run's
    j["branched_from"] = nlohmann::ordered_json::parse(branch);
  if (std::ifstream start(out + "/start.json"); start)  // the first minimum was relaxed from a frame of mrf run
    j["started_from"] = nlohmann::ordered_json::parse(start);
  j["seed"] = scene.config.seed;
  j["version"] = mrf::version();
  j["git_revision"] = mrf::git_revision();
  mrf::write_file_atomic(out + "/summary.json", j.dump(2) + "\n");
  std::printf("quasistatic %s: steady wall stress %.5g +- %.2g Pa = %.4g +- %.2g phi mu0 M^2 (virial %.5g +- %.2g Pa), "
              "%zu minima, %.1f s -> %s/summary.json\n",
              scene_path.c_str(), r.steady_wall.mean, r.steady_wall.sem, r.steady_wall.mean / r.stress_scale,
              r.steady_wall.sem / r.stress_scale, r.steady_virial.mean, r.steady_virial.sem, r.strain.size(),
              r.wall_seconds, out.c_str());
  return 0;
}
