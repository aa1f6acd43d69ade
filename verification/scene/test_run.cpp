// The run driver (scene/run): summary.json and
// timeseries.csv as DESIGN.md §Interfaces lists them, the bookkeeping between
// the stress parts and the Mason number, bitwise determinism for a fixed seed
// and thread count, the NumericalError guards of DemModel (non-finite
// state, contact stability limit) and the scheme the base run reports. The
// time-step choice and the auto rule: test_time_step.cpp.
//
// Runs use the small scene of experiments/scenes/small_dem_stokes.toml cut to
// strain 0.3 (warm-up 0.1), about 2500 steps, 1-2 s each.
#include <gtest/gtest.h>

#include "mrf/version.hpp"

#include <nlohmann/json.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/timeseries.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/run.hpp"
#include "support/files.hpp"
#include "support/small_scene.hpp"

namespace mrf {
namespace {

namespace fs = std::filesystem;

using namespace mrf::test;

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

struct RunResult {
  LoadedScene scene;
  RunSummary summary;
  std::string json, timeseries;  // file contents
  TimeSeriesTable table;         // timeseries.csv as the library reads it back
};

RunResult run(const std::vector<std::string>& overrides = {}) {
  RunResult r{scene(overrides), {}, {}, {}, {}};
  const TempDir dir("run");
  r.summary = run_scene(r.scene, RunOptions{dir.path().string(), true});
  r.json = read_bytes(dir.path() / "summary.json");
  r.timeseries = read_bytes(dir.path() / "timeseries.csv");
  if (fs::exists(dir.path() / "timeseries.csv")) r.table = read_timeseries((dir.path() / "timeseries.csv").string());
  return r;
}

// The unmodified scene, run once per process.
const RunResult& base_run() {
  static const RunResult r = run();
  return r;
}

TEST(RunOutput, TimeseriesHasOneRowPerOutputInterval) {
  const RunResult& r = base_run();
  const RunSummary& s = r.summary;
  // read_timeseries refuses a row of another length or a field that is not a number
  const TimeSeriesTable& csv = r.table;
  ASSERT_GE(csv.names.size(), 8u);
  EXPECT_EQ(csv.names[0], "time_s");
  EXPECT_EQ(csv.names[1], "strain");
  const auto& strain = csv.column("strain");
  const auto& time = csv.column("time_s");
  const auto& total = csv.column("stress_total_Pa");
  const auto& particles = csv.column("stress_particles_Pa");
  const auto& fluid = csv.column("stress_fluid_Pa");
  ASSERT_EQ(strain.size(), static_cast<std::size_t>((s.steps + k_every - 1) / k_every));
  const double step_strain = s.shear_rate * s.dt;
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    for (const auto& c : csv.columns) EXPECT_TRUE(std::isfinite(c[i])) << "row " << i;
    if (i > 0) {
      EXPECT_GT(strain[i], strain[i - 1]) << "row " << i;
    }
    const long n_step = std::min<long>(static_cast<long>(i + 1) * k_every, s.steps);
    EXPECT_NEAR(strain[i], static_cast<double>(n_step) * step_strain, 1e-5 * strain[i]) << i;
    EXPECT_NEAR(time[i] * s.shear_rate, strain[i], 1e-5 * strain[i]) << "row " << i;
    EXPECT_NEAR(total[i], particles[i] + fluid[i], 1e-5 * std::abs(total[i])) << i;
    if (strain[i] - static_cast<double>(k_every) * step_strain >= k_warmup - 1e-12) {  // whole row after warm-up
      sum += total[i];
      ++n;
    }
  }
  const double last = strain.back();
  EXPECT_GE(last, k_strain * (1 - 1e-6));
  EXPECT_LE(last, k_strain + step_strain * (1 + 1e-4));
  // The summary averages the rows after the warm-up (6 digits in the file).
  ASSERT_GT(n, 16);
  EXPECT_NEAR(sum / n, s.stress_total.mean, 1e-5 * s.stress_total.mean);
}

TEST(RunOutput, StressPartsAddUpAndMasonFollowsTheDefinition) {
  const nlohmann::json j = nlohmann::json::parse(base_run().json);
  const double total = j["stress_total"], particles = j["stress_particles"],
               fluid = j["stress_fluid"], gdot = j["shear_rate"], mason = j["mason"];
  EXPECT_LE(rel(total, particles + fluid), 1e-12) << total << " vs " << particles << " + " << fluid;
  EXPECT_LE(rel(fluid, k_eta * gdot), 1e-15);
  const double mu0 = 4e-7 * std::numbers::pi;  // REFERENCE.md (pre-2019 exact value)
  EXPECT_LE(rel(mason, 9 * k_eta * gdot / (2 * mu0 * k_m * k_m)), 1e-14);
  EXPECT_DOUBLE_EQ(mason, 1e-2);
  // Both parts count: the particles carry a sizeable part of the stress at Mn = 0.01.
  EXPECT_GT(particles, 0.1 * fluid);
}

// Model dem_dd is model 1 with one change: the drag coefficient is Di
// Felice's at Re -> 0 and the cell's mean porosity, 0.96 (1 - phi)^-2.7 times
// Stokes'; the carrier (eta gdot), the Mason number and the shear rate stay.
TEST(RunOutput, OneWayDiFeliceModelChangesOnlyTheDragCoefficient) {
  const double phi = 0.30;  // the small scene's
  const DemParams stokes = dem_params(scene().config), dd = dem_params(scene({"scene.model=dem_dd"}).config);
  EXPECT_LE(rel(dd.gamma / stokes.gamma, 0.96 * std::pow(1 - phi, -2.7)), 1e-12);
  EXPECT_LE(rel(stokes_number(stokes) / stokes_number(dd), dd.gamma / stokes.gamma), 1e-12);
  EXPECT_EQ(dd.moment, stokes.moment);
  EXPECT_EQ(dd.hertz_k, stokes.hertz_k);
  const RunResult r = run({"scene.model=dem_dd"});
  const nlohmann::json j = nlohmann::json::parse(r.json), j1 = nlohmann::json::parse(base_run().json);
  EXPECT_EQ(j["model"], "dem_dd");
  EXPECT_EQ(j["n_fluid"], 0);
  EXPECT_EQ(j["shear_rate"], j1["shear_rate"]);
  EXPECT_EQ(j["mason"], j1["mason"]);
  EXPECT_LE(rel(j["stress_fluid"].get<double>(), k_eta * j["shear_rate"].get<double>()), 1e-15);
  // the stronger drag changes the particles' stress: the run is not model 1 renamed
  EXPECT_NE(j["stress_particles"].get<double>(), j1["stress_particles"].get<double>());
}

// ---- determinism ------------------------------------------------------------

void expect_identical(const RunResult& a, const RunResult& b) {
  EXPECT_TRUE(same_bits(a.summary.stress_total.mean, b.summary.stress_total.mean))
      << g17(a.summary.stress_total.mean) << " vs " << g17(b.summary.stress_total.mean);
  EXPECT_TRUE(same_bits(a.summary.stress_virial.mean, b.summary.stress_virial.mean))
      << g17(a.summary.stress_virial.mean) << " vs " << g17(b.summary.stress_virial.mean);
  EXPECT_TRUE(same_bits(a.summary.max_overlap_over_radius, b.summary.max_overlap_over_radius))
      << g17(a.summary.max_overlap_over_radius) << " vs " << g17(b.summary.max_overlap_over_radius);
  EXPECT_FALSE(a.timeseries.empty());
  EXPECT_TRUE(a.timeseries == b.timeseries) << "timeseries.csv differs";
}

TEST(RunDeterminism, SameSeedOneThreadIsBitwiseIdentical) {
  const RunResult& a = base_run();
  ASSERT_EQ(a.scene.config.threads, 1);
  EXPECT_EQ(a.summary.threads, 1);
  expect_identical(a, run());
}

TEST(RunDeterminism, SameSeedTwoThreadsIsBitwiseIdentical) {
  const RunResult a = run({"numerics.threads=2"});
  const RunResult b = run({"numerics.threads=2"});
  EXPECT_EQ(a.summary.threads, 2);
  expect_identical(a, b);
}

TEST(RunDeterminism, AnotherSeedGivesAnotherStress) {
  const RunResult& a = base_run();
  const RunResult b = run({"scene.seed=2"});
  EXPECT_NE(a.summary.stress_total.mean, b.summary.stress_total.mean);
  EXPECT_NE(a.timeseries, b.timeseries);
  // Same scene otherwise.
  EXPECT_EQ(a.summary.n_particles, b.summary.n_particles);
  EXPECT_EQ(a.summary.dt, b.summary.dt);
}

// ---- numerical guards of DemModel ------------------------------------------

struct Parts {
  LoadedScene scene;
  ShearCell cell;
  DemParams params;
  double dt;
};

Parts parts() {
  Parts p{scene(), {}, {}, 0};
  p.cell = build_shear_cell(p.scene.config);
  p.params = dem_params(p.scene.config);
  p.dt = choose_time_step(p.scene, p.params).dt;
  return p;
}

std::string numerical_error(Parts p, double dt, bool step = false) {
  try {
    DemModel m(std::move(p.cell), p.params, IntegratorId::verlet_exp, dt);
    if (step)
      for (int n = 0; n < 10; ++n) m.step();
  } catch (const NumericalError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no NumericalError";
  return "";
}

constexpr double k_nan = std::numeric_limits<double>::quiet_NaN();

TEST(RunNumericalErrors, NanPositionNamesTheParticleAndTheStep) {
  Parts p = parts();
  ASSERT_GT(p.cell.free.size(), 10u);
  p.cell.free.x[3] = Vec3(k_nan, k_nan, k_nan);
  const double dt = p.dt;
  const std::string msg = numerical_error(std::move(p), dt);
  EXPECT_NE(msg.find("particle 3 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("position"), std::string::npos) << msg;
}

TEST(RunNumericalErrors, NanVelocityIsCaughtBeforeTheFirstStep) {
  Parts p = parts();
  p.cell.free.v[3] = Vec3(k_nan, 0, 0);
  const double dt = p.dt;
  const std::string msg = numerical_error(std::move(p), dt, true);
  EXPECT_NE(msg.find("particle 3 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("velocity"), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 0 "), std::string::npos) << msg;
}

TEST(RunNumericalErrors, ForceBlowUpNamesTheParticleAndTheStep) {
  Parts p = parts();
  p.cell.free.x[4] = p.cell.free.x[3];  // coincident centres: 0/0 in every pair force
  const double dt = p.dt;
  const std::string msg = numerical_error(std::move(p), dt);
  EXPECT_NE(msg.find("force"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle 3 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 0"), std::string::npos) << msg;
}

TEST(RunNumericalErrors, OverlapBeyondTheContactLimitStopsTheRun) {
  Parts p = parts();
  const double r = p.params.radius;
  p.cell.free.x[4] = p.cell.free.x[3] + Vec3(1.9 * r, 0, 0);  // overlap 0.1 R
  const double dt = 50 * p.dt;
  const std::string msg = numerical_error(std::move(p), dt, true);
  EXPECT_NE(msg.find("contact stability limit"), std::string::npos) << msg;
  EXPECT_NE(msg.find("step 0"), std::string::npos) << msg;

  // Without the forced overlap the 50x step still leaves the limit within a few steps.
  Parts q = parts();
  const double dt2 = 50 * q.dt;
  const std::string msg2 = numerical_error(std::move(q), dt2, true);
  EXPECT_NE(msg2.find("contact stability limit"), std::string::npos) << msg2;
}

// ---- the integrator choice -------------------------------------------------

TEST(RunIntegratorChoice, SmallSceneIsBoundByHertzContactWithVerletExp) {
  const RunResult& r = base_run();
  EXPECT_EQ(r.summary.integrator, "verlet_exp");
  EXPECT_EQ(r.summary.binding_limit, "hertz contact");
  const nlohmann::json j = nlohmann::json::parse(r.json);
  EXPECT_EQ(j["integrator"], "verlet_exp");
  EXPECT_EQ(j["dt_bound_by"], "hertz contact");
  const DemParams p = dem_params(r.scene.config);
  const auto ve = dem_limits(p, r.scene.config.gap, IntegratorId::verlet_exp);
  const auto od = dem_limits(p, r.scene.config.gap, IntegratorId::overdamped);
  EXPECT_GT(smallest(ve), smallest(od));
  EXPECT_EQ(r.summary.dt, r.scene.config.dt_safety * smallest(ve));
}

}  // namespace
}  // namespace mrf

namespace mrf {
namespace {

// A full disk (the time series goes to /dev/full, which refuses every write
// with ENOSPC): the run stops at the first row it cannot write, with an
// OutputError naming the file, the step and the system's reason, and leaves
// no summary.json that would mark it finished.
TEST(RunOutput, AFullDiskStopsTheRunNamingTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const mrf::test::TempDir dir("full_disk");
  std::filesystem::create_symlink("/dev/full", dir.path() / "timeseries.csv");
  const LoadedScene s = mrf::test::scene({});
  try {
    run_scene(s, RunOptions{dir.path().string(), true});
    ADD_FAILURE() << "the run went on with a full disk";
  } catch (const OutputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("timeseries.csv at step"), std::string::npos) << w;
    EXPECT_NE(w.find(std::strerror(ENOSPC)), std::string::npos) << w;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "summary.json"));
}

}  // namespace
}  // namespace mrf
