// The sweep driver: estimate, run the unfinished points of this rank, report
// progress, collect sweep.csv.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <system_error>

#include "mrf/box.hpp"
#include "mrf/error.hpp"
#include "mrf/scene/fluid_only.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/study/point_claim.hpp"
#include "mrf/study/sweep.hpp"
#include "mrf/vec.hpp"

namespace mrf {
namespace {

double estimate_seconds(const LoadedScene& scene, double cost_rate) {
  const SceneConfig& c = scene.config;
  const double volume = c.gap * c.ly * c.lz;
  const double n_free = c.volume_fraction * volume / sphere_volume(c.radius);
  if (n_free == 0) return std::numeric_limits<double>::quiet_NaN();
  const DemParams p = dem_params(c);
  const TimeStepChoice ts = choose_time_step(scene, p);
  const double n_wall = c.wall_spacing > 0 ? 2.0 * (c.ly / c.wall_spacing) * (c.lz / c.wall_spacing) : 0.0;
  double particles = n_free + n_wall;
  if (!is_one_way(c.model) && c.sph_spacing > 0)
    particles += volume / (c.sph_spacing * c.sph_spacing * c.sph_spacing);
  const double steps = c.strain / (c.shear_rate * ts.dt);
  return steps * particles / cost_rate;
}

// What the coupled and fluid-only runs check first (FluidParams::validate of
// the scene's fluid against the box, in build_fluid_cell), done here for
// every SPH point before any point runs, so that a bad sph_spacing does not
// surface only when the sweep reaches the point. The error names the point,
// the key with its location and the value.
void validate_point_fluid(const SweepPoint& p, const LoadedScene& scene) {
  const SceneConfig& c = scene.config;
  if (is_one_way(c.model)) return;  // no fluid
  try {
    fluid_params_from_scene(c).validate(Box{c.gap, c.ly, c.lz});
  } catch (const InputError& e) {
    throw InputError(e.key(), "", scene.locate(e.key()),
                     "sweep point " + p.dir + " (" + p.model + ", Mn " + format_number(p.mason) + ", seed " +
                         std::to_string(p.seed) + "): " + e.what());
  }
}

std::string format_seconds(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "unknown";
  if (s < 120) std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 7200) std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  return buf;
}

}  // namespace

void report_archive(const ArchiveSync& sync, const std::string& archive_dir, bool quiet) {
  if (quiet) return;
  if (sync.restored > 0)
    std::fprintf(stderr, "mrf sweep: %zu finished points restored from the archive %s\n", sync.restored,
                 archive_dir.c_str());
  if (sync.archived > 0)
    std::fprintf(stderr, "mrf sweep: %zu points finished in the output but missing from the archive %s: archived\n",
                 sync.archived, archive_dir.c_str());
  if (sync.series_added > 0)
    std::fprintf(stderr, "mrf sweep: %zu archive entries got their window series from the runs in the output\n",
                 sync.series_added);
  for (const std::string& d : sync.stale)
    std::fprintf(stderr, "mrf sweep: archive entry %s/%s is for another scene (scene_id differs): ignored, the point runs\n",
                 archive_dir.c_str(), d.c_str());
}

double estimate_point_seconds(const std::string& scene_path, const std::vector<std::string>& sets, double cost_rate) {
  try {
    return estimate_seconds(load_scene(scene_path, sets), cost_rate);
  } catch (const InputError&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

PointEstimates estimate_points(const SweepSpec& spec, const std::vector<SweepPoint>& points, const std::string& out_dir,
                               double cost_rate, const std::string& archive_dir,
                               const std::vector<std::string>& calibrate_dirs) {
  struct Measured {
    std::string model;
    double log_mn, per_strain, wall;
  };
  std::vector<Measured> done(points.size(), Measured{"", 0, -1, -1});
  for (std::size_t k = 0; k < points.size(); ++k) {
    // A point finished under out_dir is its own estimate; one only in the
    // archive (a --point run restores no other point, and an archived entry
    // of an edited scene is re-run) or in the calibration folder, or a
    // stale one under out_dir (a run for another scene, e.g. before a rule
    // changed its strain), calibrates by its seconds per strain unit.
    auto path = std::filesystem::path(out_dir) / points[k].dir / "summary.json";
    const bool present = std::filesystem::exists(path);
    const bool own = present && !point_stale(spec, points[k], path.parent_path());
    if (!present) {
      // the calibration folder may be a sweep without this sweep's
      // variants: the same model, Mn and seed there calibrate too
      std::string plain = points[k].dir;
      if (!points[k].variant.empty()) plain.erase(points[k].model.size() + 1, points[k].variant.size() + 1);
      // where to look, in order: the archive, then each calibration folder
      // for the point itself and then for its plain form
      std::vector<std::filesystem::path> where;
      if (!archive_dir.empty()) where.push_back(std::filesystem::path(archive_dir) / points[k].dir);
      for (const std::string& d : calibrate_dirs) {
        where.push_back(std::filesystem::path(d) / points[k].dir);
        where.push_back(std::filesystem::path(d) / plain);
      }
      bool found = false;
      for (const auto& w : where)
        if (!found && std::filesystem::exists(w / "summary.json")) {
          path = w / "summary.json";
          found = true;
        }
      // then the same model (and variant) and Mn at another seed in a
      // calibration folder, the first by folder name (a sweep of more seeds
      // of a finished point, estimated before any of its runs)
      const std::string name = std::filesystem::path(points[k].dir).filename().string();
      const std::size_t seed_at = name.rfind("_seed_");
      for (const std::string& d : calibrate_dirs) {
        if (found || seed_at == std::string::npos) break;
        const auto folder = std::filesystem::path(d) / std::filesystem::path(points[k].dir).parent_path();
        const std::string prefix = name.substr(0, seed_at + 6);
        std::error_code ec;
        std::vector<std::filesystem::path> others;
        for (const auto& e : std::filesystem::directory_iterator(folder, ec))
          if (e.path().filename().string().rfind(prefix, 0) == 0 && std::filesystem::exists(e.path() / "summary.json"))
            others.push_back(e.path() / "summary.json");
        std::sort(others.begin(), others.end());
        if (!others.empty()) {
          path = others.front();
          found = true;
        }
      }
      if (!found) continue;
    }
    try {
      std::ifstream in(path);
      const nlohmann::json j = nlohmann::json::parse(in);
      done[k] = {points[k].model, std::log(points[k].mason), j.at("seconds_per_strain").get<double>(),
                 own ? j.at("wall_seconds").get<double>() : -1.0};
    } catch (const std::exception&) {  // an unreadable summary calibrates nothing
    }
  }
  PointEstimates e;
  e.seconds.resize(points.size());
  e.calibrated.assign(points.size(), 0);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (done[k].wall >= 0) {
      e.seconds[k] = done[k].wall;
      e.calibrated[k] = 1;
      continue;
    }
    // its own earlier run (stale, archived or in the calibration folder)
    // first, else the nearest Mn of the model
    const Measured* near = done[k].per_strain > 0 ? &done[k] : nullptr;
    if (!near)
      for (const Measured& m : done)
        if (m.per_strain > 0 && m.model == points[k].model &&
            (!near || std::abs(m.log_mn - std::log(points[k].mason)) < std::abs(near->log_mn - std::log(points[k].mason))))
          near = &m;
    if (near) {
      try {
        e.seconds[k] = near->per_strain * load_scene(spec.scene_path, points[k].sets).config.strain;
        e.calibrated[k] = 1;
        continue;
      } catch (const InputError&) {
      }
    }
    e.seconds[k] = estimate_point_seconds(spec.scene_path, points[k].sets, cost_rate);
  }
  return e;
}

SweepOutcome run_sweep(const SweepSpec& spec, const std::string& out_dir, const SweepOptions& opt) {
  const std::vector<SweepPoint> points = sweep_points(spec);
  if (opt.point >= static_cast<long>(points.size()))
    throw InputError("--point", std::to_string(opt.point), "",
                     "the grid has " + std::to_string(points.size()) + " points, 0 to " +
                         std::to_string(points.size() - 1) + " (mrf sweep FILE --list)");
  const auto mine = opt.point >= 0 ? std::vector<std::size_t>{static_cast<std::size_t>(opt.point)}
                                   : points_of_rank(points.size(), opt.rank.rank, opt.rank.size);
  SweepOutcome outcome;
  struct Todo {
    const SweepPoint* point;
    LoadedScene scene;
    double estimate;
  };
  std::vector<Todo> todo;
  std::vector<SweepPoint> share;
  for (std::size_t i : mine) share.push_back(points[i]);
  set_aside_stale(spec, share, out_dir, opt.quiet);
  if (!opt.archive.empty())
    report_archive(restore_from_archive(spec, share, out_dir, opt.archive), opt.archive, opt.quiet);
  const PointEstimates calibrated = estimate_points(spec, points, out_dir, opt.cost_rate, opt.archive, opt.calibrate);
  for (std::size_t i : mine) {
    const SweepPoint& p = points[i];
    if (point_finished(spec, p, out_dir)) {
      ++outcome.skipped;
      continue;
    }
    LoadedScene scene = load_scene(spec.scene_path, p.sets);  // input errors stop the sweep here
    validate_point_fluid(p, scene);                             // and those of the fluid of a coupled model
    double est = calibrated.calibrated[i] ? calibrated.seconds[i] : std::numeric_limits<double>::quiet_NaN();
    if (!calibrated.calibrated[i]) try {
        est = estimate_seconds(scene, opt.cost_rate);
      } catch (const InputError&) {
        // not estimable (e.g. a time-step rule of a model the estimate does not know); run it anyway
      }
    // a run under way resumes from its checkpoint: only the rest of its strain is to go
    est *= point_fraction_left(spec, p, out_dir);
    todo.push_back({&p, std::move(scene), est});
  }
  double known = 0;
  std::size_t unknown = 0;
  for (const auto& t : todo) {
    if (std::isfinite(t.estimate)) known += t.estimate;
    else ++unknown;
  }
  outcome.estimated_seconds = known;
  if (!opt.quiet)
    std::fprintf(stderr,
                 "mrf sweep: %zu points in the grid, %s runs %zu (%zu already finished); "
                 "estimated cost %s at %.3g particle-steps/s%s\n",
                 points.size(),
                 (opt.point >= 0 ? "--point " + std::to_string(opt.point)
                                 : "rank " + std::to_string(opt.rank.rank) + " of " + std::to_string(opt.rank.size))
                     .c_str(),
                 mine.size(), outcome.skipped,
                 format_seconds(known).c_str(), opt.cost_rate,
                 unknown ? (" (+" + std::to_string(unknown) + " points not estimable)").c_str() : "");

  const auto t0 = std::chrono::steady_clock::now();
  double spent_estimated = 0, spent_actual = 0, left_estimated = known;
  for (std::size_t k = 0; k < todo.size(); ++k) {
    const Todo& t = todo[k];
    const std::string dir = (std::filesystem::path(out_dir) / t.point->dir).string();
    // Another process on this sweep output may run the point now, or have
    // finished it since this one listed its points (point_claim.hpp).
    const PointClaim claim(dir);
    if (claim.owned()) {  // what the start could not do while another process held the point
      set_aside_stale(spec, {*t.point}, out_dir, opt.quiet, true);
      if (!opt.archive.empty())
        report_archive(restore_from_archive(spec, {*t.point}, out_dir, opt.archive, true), opt.archive, opt.quiet);
    }
    if (!claim.owned() || point_finished(dir)) {
      if (std::isfinite(t.estimate)) left_estimated -= t.estimate;
      if (!claim.owned()) {
        ++outcome.elsewhere;
        if (!opt.quiet)
          std::fprintf(stderr, "mrf sweep: [%zu/%zu] %s is being run by %s: left to it\n", k + 1, todo.size(),
                       t.point->dir.c_str(), claim.holder().c_str());
      } else {
        ++outcome.skipped;
      }
      continue;
    }
    if (point_record_damaged(dir))  // said even when quiet: a record was lost
      std::fprintf(stderr, "mrf sweep: point %s: its summary.json or failure.json does not read (a damaged file): "
                           "the point runs again\n", t.point->dir.c_str());
    if (!opt.quiet)
      std::fprintf(stderr, "mrf sweep: [%zu/%zu] %s Mn=%g seed %llu -> %s\n", k + 1, todo.size(),
                   t.point->model.c_str(), t.point->mason, static_cast<unsigned long long>(t.point->seed), dir.c_str());
    const auto p0 = std::chrono::steady_clock::now();
    try {
      RunOptions ro;
      ro.out_dir = dir;
      ro.quiet = true;
      ro.resume = true;  // a point killed mid-run continues from its last checkpoint
      ro.checkpoint_seconds = opt.checkpoint_seconds;
      const RunSummary s = run_scene(t.scene, ro);
      ++outcome.ran;
      if (!opt.archive.empty()) archive_point(*t.point, out_dir, opt.archive);
      if (!opt.quiet)
        std::fprintf(stderr, "           stress_total = %.5g +- %.2g Pa, drift z = %.2f\n", s.stress_total.mean,
                     s.stress_total.err, s.stress_total.drift_z);
    } catch (const OutputError&) {
      // a full disk or an unwritable folder: stop the sweep, and leave the
      // point resumable (no failure.json, which would mark it done)
      throw;
    } catch (const std::system_error& e) {  // the same from the system (filesystem_error, ios_base::failure)
      throw OutputError("point " + t.point->dir + ": " + e.what() + " (the sweep stops; the point stays resumable)");
    } catch (const CheckpointError& e) {
      // a checkpoint of another format version (written by another build)
      // or a damaged one: not the point's physics, so no failure.json; the
      // point keeps its checkpoint and the sweep goes on with the others
      ++outcome.refused;
      std::fprintf(stderr,
                   "mrf sweep: point %s not run: checkpoint refused: %s\n"
                   "           (the folder is left as it is; deleting %s/checkpoint.bin runs the point from its start)\n",
                   t.point->dir.c_str(), e.what(), dir.c_str());
    } catch (const std::runtime_error& e) {  // NumericalError, or an InputError only the run can see
      ++outcome.failed;
      std::filesystem::create_directories(dir);
      nlohmann::json j{{"model", t.point->model}, {"mason", t.point->mason}, {"seed", t.point->seed},
                       {"scene_id", scene_id(t.scene.config)}, {"error", e.what()}};
      write_file_atomic(dir + "/failure.json", j.dump(2) + "\n");
      std::fprintf(stderr, "mrf sweep: point %s failed: %s\n", t.point->dir.c_str(), e.what());
    }
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - p0).count();
    if (std::isfinite(t.estimate)) {
      spent_estimated += t.estimate;
      spent_actual += took;
      left_estimated -= t.estimate;
    }
    if (!opt.quiet) {
      const double scale = spent_estimated > 0 ? spent_actual / spent_estimated : 1.0;
      std::fprintf(stderr, "           took %s; about %s left (estimate x %.2f measured so far)\n",
                   format_seconds(took).c_str(), format_seconds(std::max(0.0, left_estimated * scale)).c_str(), scale);
    }
  }
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (opt.write_csv) write_sweep_csv(points, out_dir, &spec);
  return outcome;
}

}  // namespace mrf
