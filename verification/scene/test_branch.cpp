// Branches (mrf run --branch-from): a run that starts from another run's
// state. With the same numerics it continues the parent's trajectory row for
// row; it may change the numerical choices (the implicit tolerance here) but
// no physical key; its strain and warm-up count from the branch point, and
// so does its summary's work (steps, list builds, Newton and CG
// iterations); the final state a run keeps (--keep-final-state) is a valid
// parent.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {
namespace {

const std::string k_scene = MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml";
const std::string k_coupled = MRF_SOURCE_DIR "/experiments/scenes/small_demsph_dd.toml";

// explicit steps (their automatic size, 3.13e-3 strain for model 1, is bound
// by the wall speed, not by the run's length) and rows of two steps, so that a
// parent and a branch cut the same steps into the same rows
LoadedScene scene(double strain, double warmup, const std::string& path = k_scene) {
  return load_scene(path, {"drive.mason=1.0", "drive.strain=" + std::to_string(strain),
                           "drive.warmup_strain=" + std::to_string(warmup), "output.every=2", "output.frames=0"});
}

// rows of timeseries.csv: time, strain, then the stress columns as text (bit for bit)
struct Row {
  double time, strain;
  std::string rest;
};
std::vector<Row> rows(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);  // header
  std::vector<Row> out;
  while (std::getline(in, line)) {
    const std::size_t a = line.find(','), b = line.find(',', a + 1);
    out.push_back({std::stod(line.substr(0, a)), std::stod(line.substr(a + 1, b - a - 1)), line.substr(b + 1)});
  }
  return out;
}

std::filesystem::path fresh(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("mrf_branch_" + name);
  std::filesystem::remove_all(d);
  return d;
}

void check_continues_parent(const std::string& path, const std::string& name) {
  const auto base = fresh(name);
  // the parent, cut at a row boundary: its checkpoint is the branch point
  RunOptions cut;
  cut.out_dir = (base / "parent").string();
  cut.quiet = true;
  cut.checkpoint_every_rows = 20;
  cut.stop_after_steps = 55;  // the checkpoint after row 20 (step 40)
  EXPECT_THROW(run_scene(scene(0.6, 0.1, path), cut), RunInterrupted);
  const auto state = base / "state.bin";
  std::filesystem::copy_file(base / "parent/checkpoint.bin", state);
  cut.stop_after_steps = 0;
  cut.resume = true;
  const RunSummary p = run_scene(scene(0.6, 0.1, path), cut);  // the parent to its end
  ASSERT_NE(p.integrator.find("verlet"), std::string::npos) << p.integrator;  // fixed steps
  const std::vector<Row> parent = rows(base / "parent/timeseries.csv");
  ASSERT_GT(parent.size(), 90u);
  const double t0 = parent[19].time, s0 = parent[19].strain;

  RunOptions br;
  br.out_dir = (base / "branch").string();
  br.quiet = true;
  br.branch_from = state.string();
  const RunSummary b = run_scene(scene(0.6 - s0, 0.05, path), br);
  const std::vector<Row> branch = rows(base / "branch/timeseries.csv");
  ASSERT_GT(branch.size(), 50u);
  EXPECT_NEAR(b.strain, 0.6 - s0, 1e-6);  // drive.strain as set (six digits)
  for (std::size_t k = 0; k + 1 < branch.size() && 20 + k < parent.size(); ++k) {
    ASSERT_EQ(branch[k].rest, parent[20 + k].rest) << "row " << k << " of the branch";
    EXPECT_NEAR(branch[k].time, parent[20 + k].time - t0, 1e-9 * parent.back().time);  // its own clock
    EXPECT_NEAR(branch[k].strain, parent[20 + k].strain - s0, 1e-8);
  }
  EXPECT_NEAR(branch.back().strain, 0.6 - s0, 0.004);  // drive.strain from the branch point, within a step
  // Its work is its own: the same steps as the parent's after step 40 (to
  // within the last one), and the parent's list builds less those of its
  // first 40 steps (at least the first build).
  // (the coupled model's steps are DEM sub-steps, `substeps` to a step of the loop)
  const long substeps = p.extra.count("fluid_steps") ? p.steps / static_cast<long>(p.extra.at("fluid_steps")) : 1;
  ASSERT_GE(substeps, 1);
  EXPECT_LE(std::abs(b.steps - (p.steps - 40 * substeps)), substeps);
  EXPECT_GE(p.neighbor_builds - b.neighbor_builds, 1);
  EXPECT_LE(p.neighbor_builds - b.neighbor_builds, 40);
  if (p.extra.count("fluid_steps")) {
    EXPECT_LE(std::abs(b.extra.at("fluid_steps") - (p.extra.at("fluid_steps") - 40)), 1.0);
  }
}

TEST(Branch, WithTheSameNumericsContinuesTheParentRowForRow) { check_continues_parent(k_scene, "same"); }
TEST(Branch, WithTheSameNumericsContinuesACoupledParentRowForRow) { check_continues_parent(k_coupled, "coupled"); }

TEST(Branch, WarmUpCountsFromTheBranchPoint) {
  const auto base = fresh("warmup");
  RunOptions parent;
  parent.out_dir = (base / "parent").string();
  parent.quiet = true;
  parent.keep_final_state = true;
  run_scene(scene(0.3, 0.1), parent);
  ASSERT_TRUE(std::filesystem::exists(base / "parent/final_state.bin"));
  ASSERT_FALSE(std::filesystem::exists(base / "parent/checkpoint.bin"));

  RunOptions br;
  br.out_dir = (base / "branch").string();
  br.quiet = true;
  br.branch_from = (base / "parent/final_state.bin").string();
  const RunSummary b = run_scene(scene(0.5, 0.2), br);
  // the window's mean: the rows whose start is at or after 0.2 of the branch's own strain
  const std::vector<Row> r = rows(base / "branch/timeseries.csv");
  double sum = 0;
  int n = 0;
  for (std::size_t k = 1; k < r.size(); ++k)
    if (r[k - 1].strain >= 0.2 * (1 - 1e-12)) sum += std::stod(r[k].rest.substr(0, r[k].rest.find(','))), ++n;
  ASSERT_GT(n, 32);
  EXPECT_NEAR(b.stress_total.mean, sum / n, 1e-9 * std::abs(sum / n));
}

TEST(Branch, MayChangeTheToleranceButNoPhysicalKey) {
  const auto base = fresh("keys");
  auto implicit_scene = [&](double strain, std::vector<std::string> more) {
    std::vector<std::string> sets = {"drive.mason=1.0", "drive.strain=" + std::to_string(strain),
                                     "drive.warmup_strain=0.05", "numerics.integrator=\"implicit\"",
                                     "output.frames=0"};
    sets.insert(sets.end(), more.begin(), more.end());
    return load_scene(k_scene, sets);
  };
  RunOptions parent;
  parent.out_dir = (base / "parent").string();
  parent.quiet = true;
  parent.keep_final_state = true;
  const RunSummary p = run_scene(implicit_scene(1.2, {}), parent);
  RunOptions br;
  br.quiet = true;
  br.branch_from = (base / "parent/final_state.bin").string();
  br.out_dir = (base / "tol").string();
  const RunSummary b = run_scene(implicit_scene(0.3, {"numerics.implicit_tol=0.0025"}), br);
  EXPECT_TRUE(std::isfinite(b.stress_total.mean));
  EXPECT_GT(b.steps, 0);

  // the branch's own implicit work: at least a Newton iteration a step, and
  // less than the longer parent's (a branch that carried its parent's
  // counters would report more), and its mean step its own
  br.out_dir = (base / "short").string();
  const RunSummary sh = run_scene(implicit_scene(0.05, {"drive.warmup_strain=0.01"}), br);
  EXPECT_GE(sh.extra.at("implicit_newton_iterations"), static_cast<double>(sh.steps));
  EXPECT_LT(sh.extra.at("implicit_newton_iterations"), p.extra.at("implicit_newton_iterations"));
  EXPECT_LT(sh.extra.at("implicit_linear_iterations"), p.extra.at("implicit_linear_iterations"));
  EXPECT_LT(sh.neighbor_builds, p.neighbor_builds);
  EXPECT_NEAR(sh.extra.at("implicit_dt_mean"), 0.05 / sh.shear_rate / static_cast<double>(sh.steps),
              1e-6 * sh.extra.at("implicit_dt_mean"));

  br.out_dir = (base / "field").string();
  try {
    run_scene(implicit_scene(0.3, {"particles.magnetization=5e5"}), br);
    FAIL() << "a branch into another magnetisation ran";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--branch-from"), std::string::npos) << what;
    EXPECT_NE(what.find("particles.magnetization"), std::string::npos) << what;
  }
  br.out_dir = (base / "integrator").string();
  EXPECT_THROW(run_scene(implicit_scene(0.3, {"numerics.integrator=\"verlet_exp\""}), br), InputError);
  EXPECT_FALSE(std::filesystem::exists(base / "field/summary.json"));
}

TEST(Branch, OnlyNumericalKeysMayDiffer) {
  for (const char* k : {"numerics.implicit_tol", "numerics.dt", "drive.strain", "drive.warmup_strain", "scene.seed",
                        "output.every"})
    EXPECT_TRUE(branch_may_differ_in(k)) << k;
  // numerics.skin: the lists (and their skin) are the parent's state
  for (const char* k : {"numerics.skin", "particles.magnetization", "drive.shear_rate", "drive.mason", "scene.model",
                        "numerics.integrator", "numerics.implicit_order", "box.gap", "fluid.sph_spacing", "(format)"})
    EXPECT_FALSE(branch_may_differ_in(k)) << k;
}

}  // namespace
}  // namespace mrf
