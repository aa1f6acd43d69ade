// The run driver (scene/run): the time-step choice and its refusal of a user
// dt above the stability limit (DESIGN.md §Numerics), summary.json and
// timeseries.csv as DESIGN.md §Interfaces lists them, the bookkeeping between
// the stress parts and the Mason number, bitwise determinism for a fixed seed
// and thread count, and the NumericalError guards of DemModel (non-finite
// state, contact stability limit).
//
// Runs use the small scene of experiments/scenes/small_dem_stokes.toml cut to
// strain 0.3 (warm-up 0.1), about 2500 steps, 1-2 s each.
#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

namespace fs = std::filesystem;

const std::string k_source = "small.toml";

// experiments/scenes/small_dem_stokes.toml with a short drive, one thread and
// a time-series row every 25 steps.
const std::string k_scene = R"([scene]
model = "dem_stokes"
seed = 1

[box]
gap = "80 um"
ly = "32 um"
lz = "32 um"

[particles]
radius = "2.5 um"
volume_fraction = 0.30
density = "7800 kg/m^3"
magnetization = "1000 kA/m"
dipole_cutoff = "15 um"

[walls]
spacing = "2.5 um"

[contact]
youngs_modulus = "200 GPa"
poisson_ratio = 0.3

[fluid]
viscosity = "0.1 Pa s"
density = "1000 kg/m^3"

[drive]
mason = 1e-2
strain = 0.3
warmup_strain = 0.1

[numerics]
integrator = "verlet_exp"
dt = "auto"
threads = 1

[output]
every = 25
)";
constexpr double k_eta = 0.1, k_m = 1e6, k_strain = 0.3, k_warmup = 0.1;
constexpr int k_every = 25;

LoadedScene scene(const std::vector<std::string>& overrides = {}, const std::string& text = k_scene) {
  return parse_scene(text, k_source, overrides);
}

// 1-based number of the line of `text` that starts with `start`.
int line_of(const std::string& text, const std::string& start) {
  std::istringstream in(text);
  std::string l;
  for (int n = 1; std::getline(in, l); ++n)
    if (l.starts_with(start)) return n;
  ADD_FAILURE() << "no line starting with " << start;
  return -1;
}

std::string with_dt(const std::string& value) {
  std::string text = k_scene;
  const std::string from = "dt = \"auto\"";
  text.replace(text.find(from), from.size(), "dt = " + value);
  return text;
}

std::string g17(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

double rel(double a, double b) { return std::abs(a - b) / std::max(std::abs(a), std::abs(b)); }

// A fresh directory under the system temp dir, removed on destruction.
class TempDir {
 public:
  TempDir() {
    static int count = 0;
    path_ = fs::temp_directory_path() /
            ("mrf_test_run_" + std::to_string(::getpid()) + "_" + std::to_string(count++));
    fs::remove_all(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

struct RunResult {
  LoadedScene scene;
  RunSummary summary;
  std::string json, timeseries;  // file contents
};

RunResult run(const std::vector<std::string>& overrides = {}) {
  RunResult r{scene(overrides), {}, {}, {}};
  const TempDir dir;
  r.summary = run_scene(r.scene, RunOptions{dir.path().string(), true});
  r.json = slurp(dir.path() / "summary.json");
  r.timeseries = slurp(dir.path() / "timeseries.csv");
  return r;
}

// The unmodified scene, run once per process.
const RunResult& base_run() {
  static const RunResult r = run();
  return r;
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, sep)) out.push_back(cell);
  return out;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

Csv parse_csv(const std::string& text) {
  Csv csv;
  std::istringstream in(text);
  std::string line;
  if (std::getline(in, line)) csv.header = split(line, ',');
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (const std::string& cell : split(line, ',')) row.push_back(std::strtod(cell.c_str(), nullptr));
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

// ---- the time step -------------------------------------------------------

struct Limit {
  double dt;
  std::string name;
};

Limit binding_limit(const LoadedScene& s) {
  const TimeStepChoice t = choose_time_step(s, dem_params(s.config));
  return {binding(t.limits).dt, binding(t.limits).name};
}

std::string input_error(const LoadedScene& s) {
  try {
    choose_time_step(s, dem_params(s.config));
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "numerics.dt");
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

// The value in "... key 'numerics.dt' = VALUE: ..." read back in seconds: a
// plain number (SI) or "<number> <unit>", quoted or not.
std::optional<double> shown_dt(const std::string& message) {
  const std::string tag = "key 'numerics.dt' = ";
  std::size_t b = message.find(tag);
  if (b == std::string::npos) return std::nullopt;
  b += tag.size();
  std::string v = message.substr(b, message.find(": ", b) - b);
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end != v.c_str() && trim(end).empty()) return x;
  try {
    return parse_quantity(v, Dim::time);
  } catch (const ValueError&) {
    return std::nullopt;
  }
}

TEST(RunTimeStep, AutomaticDtIsTheSafetyFractionOfTheBindingLimit) {
  const LoadedScene s = scene();
  const TimeStepChoice t = choose_time_step(s, dem_params(s.config));
  EXPECT_EQ(t.scheme, IntegratorId::verlet_exp);
  EXPECT_DOUBLE_EQ(t.dt, s.config.dt_safety * binding(t.limits).dt);
  EXPECT_EQ(s.config.dt_safety, 0.5);
}

TEST(RunTimeStep, DtAboveTheLimitInTheFileNamesKeyValueLineAndLimit) {
  const Limit lim = binding_limit(scene());
  ASSERT_EQ(lim.name, "hertz contact");
  for (const double factor : {2.0, 1.01}) {
    const double dt = factor * lim.dt;
    const std::string text = with_dt(g17(dt));
    const std::string where = k_source + ":" + std::to_string(line_of(text, "dt = "));
    const LoadedScene s = scene({}, text);
    const std::string msg = input_error(s);
    EXPECT_NE(msg.find("numerics.dt"), std::string::npos) << msg;
    EXPECT_NE(msg.find(where), std::string::npos) << "expected " << where << " in: " << msg;
    EXPECT_NE(msg.find("'" + lim.name + "'"), std::string::npos) << msg;
    const std::optional<double> shown = shown_dt(msg);
    ASSERT_TRUE(shown.has_value()) << msg;
    EXPECT_LT(std::abs(*shown - dt), 1e-5 * dt)
        << "the message shows numerics.dt as " << *shown << " s, the file says " << dt
        << " s: " << msg;
    // run_scene refuses it too, before any work.
    EXPECT_THROW(run_scene(s, RunOptions{"", true}), InputError);
  }
  // The same with units.
  const std::string ns = g17(2e9 * lim.dt) + " ns";
  const std::string msg = input_error(scene({}, with_dt("\"" + ns + "\"")));
  const std::optional<double> shown = shown_dt(msg);
  ASSERT_TRUE(shown.has_value()) << msg;
  EXPECT_LT(std::abs(*shown - 2 * lim.dt), 1e-5 * lim.dt) << msg;
}

TEST(RunTimeStep, DtAboveTheLimitFromAnOverrideNamesTheOverride) {
  const Limit lim = binding_limit(scene());
  const std::string value = g17(2 * lim.dt);
  const std::string msg = input_error(scene({"numerics.dt=" + value}));
  EXPECT_NE(msg.find("--set numerics.dt=" + value), std::string::npos) << msg;
  EXPECT_NE(msg.find("'" + lim.name + "'"), std::string::npos) << msg;
  EXPECT_EQ(msg.find(k_source + ":"), std::string::npos) << "an override has no file line: " << msg;
  const std::optional<double> shown = shown_dt(msg);
  ASSERT_TRUE(shown.has_value()) << msg;
  EXPECT_LT(std::abs(*shown - 2 * lim.dt), 1e-5 * lim.dt) << msg;
}

TEST(RunTimeStep, DtJustBelowTheLimitPassesValidation) {
  const Limit lim = binding_limit(scene());
  for (const double factor : {0.99, 1.0}) {
    const LoadedScene s = scene({"numerics.dt=" + g17(factor * lim.dt)});
    TimeStepChoice t;
    ASSERT_NO_THROW(t = choose_time_step(s, dem_params(s.config))) << factor;
    EXPECT_EQ(t.dt, *s.config.dt);
    EXPECT_EQ(t.scheme, IntegratorId::verlet_exp);
  }
}

// A dt that validation accepts should also run: the contact limit the run
// enforces (DemModel::overlap_limit) should not stop it in the first steps.
TEST(RunTimeStep, DtJustBelowTheLimitRunsToTheEnd) {
  const Limit lim = binding_limit(scene());
  const LoadedScene s = scene({"numerics.dt=" + g17(0.99 * lim.dt)});
  try {
    const RunSummary r = run_scene(s, RunOptions{"", true});
    EXPECT_GE(r.strain, k_strain);
  } catch (const NumericalError& e) {
    ADD_FAILURE() << "numerics.dt = 0.99 x the '" << lim.name << "' limit (" << 0.99 * lim.dt
                  << " s) passed validation, but the run stopped: " << e.what();
  }
}

// ---- summary.json and timeseries.csv --------------------------------------

const char* const k_design_keys[] = {
    "model", "mason", "shear_rate", "strain", "warmup_strain", "stress_total",
    "stress_total_err", "stress_particles", "stress_fluid", "stress_virial", "n_particles",
    "n_fluid", "dt", "steps", "wall_seconds", "stokes_number", "reynolds_number",
    "max_overlap_over_radius", "version"};

TEST(RunOutput, SummaryJsonHasEveryKeyOfTheDesign) {
  const RunResult& r = base_run();
  const nlohmann::json j = nlohmann::json::parse(r.json);
  for (const char* key : k_design_keys) {
    ASSERT_TRUE(j.contains(key)) << key;
    if (std::string(key) == "model" || std::string(key) == "version") {
      EXPECT_TRUE(j[key].is_string()) << key;
    } else {
      ASSERT_TRUE(j[key].is_number()) << key << " = " << j[key].dump();
      EXPECT_TRUE(std::isfinite(j[key].get<double>())) << key << " = " << j[key].dump();
    }
  }
  const RunSummary& s = r.summary;
  EXPECT_EQ(j["model"], "dem_stokes");
  EXPECT_EQ(j["version"], MRF_VERSION);
  EXPECT_EQ(j["strain"].get<double>(), k_strain);
  EXPECT_EQ(j["warmup_strain"].get<double>(), k_warmup);
  EXPECT_EQ(j["n_particles"].get<long>(), static_cast<long>(particle_count(r.scene.config)));
  EXPECT_EQ(j["n_fluid"].get<long>(), 0);  // dem_stokes allocates no fluid
  EXPECT_EQ(j["steps"].get<long>(), s.steps);
  EXPECT_EQ(j["steps"].get<long>(),
            static_cast<long>(std::ceil(k_strain / (s.shear_rate * s.dt))));
  // The file holds the returned numbers exactly.
  EXPECT_TRUE(same_bits(j["stress_total"].get<double>(), s.stress_total.mean));
  EXPECT_TRUE(same_bits(j["stress_total_err"].get<double>(), s.stress_total.err));
  EXPECT_TRUE(same_bits(j["stress_virial"].get<double>(), s.stress_virial.mean));
  EXPECT_TRUE(same_bits(j["dt"].get<double>(), s.dt));
  EXPECT_GT(j["stress_total_err"].get<double>(), 0);
  EXPECT_GT(j["wall_seconds"].get<double>(), 0);
  EXPECT_GT(j["max_overlap_over_radius"].get<double>(), 0);
  EXPECT_LT(j["max_overlap_over_radius"].get<double>(), 0.05);
  EXPECT_NEAR(j["stokes_number"].get<double>(), dem_params(r.scene.config).tau_p * s.shear_rate,
              1e-15);
  EXPECT_DOUBLE_EQ(j["reynolds_number"].get<double>(), 1000 * s.shear_rate * 2.5e-6 * 2.5e-6 / k_eta);
}

// Non-magnetic particles (M = 0) with a given shear rate run, and the
// infinite Mason number is stated, not left as a bare null (or an "inf" that
// is no JSON): summary.json holds "mason": null beside its reason.
TEST(RunOutput, ZeroMagnetizationRunsAndStatesTheInfiniteMasonNumber) {
  const LoadedScene s = scene({"particles.magnetization=0", "drive.shear_rate=1e3"});
  ASSERT_TRUE(std::isinf(s.config.mason));
  const RunSummary r = run_scene(s, RunOptions{"", true});
  EXPECT_TRUE(std::isinf(r.mason));
  EXPECT_TRUE(std::isfinite(r.stress_total.mean));
  const std::string text = summary_json(r);
  const nlohmann::json j = nlohmann::json::parse(text);  // strict JSON
  ASSERT_TRUE(j.contains("mason"));
  EXPECT_TRUE(j["mason"].is_null()) << j["mason"].dump();
  ASSERT_TRUE(j.contains("mason_note") && j["mason_note"].is_string()) << text;
  EXPECT_NE(j["mason_note"].get<std::string>().find("particles.magnetization = 0"), std::string::npos);
  EXPECT_EQ(j["shear_rate"].get<double>(), 1e3);
  EXPECT_EQ(j["magnetization"].get<double>(), 0.0);
}

// The carrier fluid's viscosity and density are in summary.json (mrf
// criterion reads the viscosity from there, through sweep.csv).
TEST(RunOutput, SummaryJsonHasTheFluidViscosityAndDensity) {
  const RunResult& r = base_run();
  const nlohmann::json j = nlohmann::json::parse(r.json);
  ASSERT_TRUE(j.contains("viscosity") && j["viscosity"].is_number()) << r.json;
  ASSERT_TRUE(j.contains("fluid_density") && j["fluid_density"].is_number()) << r.json;
  EXPECT_EQ(j["viscosity"].get<double>(), r.scene.config.viscosity);
  EXPECT_EQ(j["viscosity"].get<double>(), k_eta);
  EXPECT_EQ(j["fluid_density"].get<double>(), 1000.0);
}

TEST(RunOutput, TimeseriesHasOneRowPerOutputInterval) {
  const RunResult& r = base_run();
  const RunSummary& s = r.summary;
  const Csv csv = parse_csv(r.timeseries);
  ASSERT_GE(csv.header.size(), 8u);
  EXPECT_EQ(csv.header[0], "time_s");
  EXPECT_EQ(csv.header[1], "strain");
  const std::size_t strain = csv.column("strain"), time = csv.column("time_s"),
                    total = csv.column("stress_total_Pa"),
                    particles = csv.column("stress_particles_Pa"),
                    fluid = csv.column("stress_fluid_Pa");
  ASSERT_EQ(csv.rows.size(), static_cast<std::size_t>((s.steps + k_every - 1) / k_every));
  const double step_strain = s.shear_rate * s.dt;
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const std::vector<double>& row = csv.rows[i];
    ASSERT_EQ(row.size(), csv.header.size()) << "row " << i;
    for (double x : row) EXPECT_TRUE(std::isfinite(x)) << "row " << i;
    if (i > 0) {
      EXPECT_GT(row[strain], csv.rows[i - 1][strain]) << "row " << i;
    }
    const long n_step = std::min<long>(static_cast<long>(i + 1) * k_every, s.steps);
    EXPECT_NEAR(row[strain], static_cast<double>(n_step) * step_strain, 1e-5 * row[strain]) << i;
    EXPECT_NEAR(row[time] * s.shear_rate, row[strain], 1e-5 * row[strain]) << "row " << i;
    EXPECT_NEAR(row[total], row[particles] + row[fluid], 1e-5 * std::abs(row[total])) << i;
    if (row[strain] - static_cast<double>(k_every) * step_strain >= k_warmup - 1e-12) {  // whole row after warm-up
      sum += row[total];
      ++n;
    }
  }
  const double last = csv.rows.back()[strain];
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

// Auto keeps the particles' inertia (verlet_exp) above the Stokes bound;
// below it, it picks the explicit scheme whose binding (smallest) limit is
// largest, ties to verlet_exp, with dt = dt_safety times that limit; unless
// that limit is more than k_implicit_preference times below the implicit
// step bound: then implicit, with dt = the bound (its largest step).
void expect_auto_rule(const LoadedScene& s, const std::string& label) {
  const DemParams p = dem_params(s.config);
  const auto ve = dem_limits(p, s.config.gap, IntegratorId::verlet_exp);
  const auto od = dem_limits(p, s.config.gap, IntegratorId::overdamped);
  const auto im = dem_limits(p, s.config.gap, IntegratorId::implicit);
  const double explicit_dt = std::max(smallest(ve), smallest(od));
  const IntegratorId want = stokes_number(p) > k_inertialess_max_stokes          ? IntegratorId::verlet_exp
                            : k_implicit_preference * explicit_dt < smallest(im) ? IntegratorId::implicit
                            : smallest(ve) >= smallest(od)                       ? IntegratorId::verlet_exp
                                                                                 : IntegratorId::overdamped;
  const TimeStepChoice t = choose_time_step(s, p);
  EXPECT_EQ(t.scheme, want) << label << ": verlet_exp limit " << smallest(ve)
                            << " s, overdamped limit " << smallest(od) << " s, implicit bound " << smallest(im);
  EXPECT_EQ(t.dt, want == IntegratorId::implicit ? smallest(im) : s.config.dt_safety * explicit_dt) << label;
  const auto& limits = want == IntegratorId::implicit ? im : want == IntegratorId::verlet_exp ? ve : od;
  EXPECT_EQ(binding(t.limits).name, binding(limits).name) << label;
}

TEST(RunIntegratorChoice, AutoPicksTheSchemeWhoseBindingLimitIsLargest) {
  for (const char* density : {"7800", "78", "7.8", "0.078"})
    for (const char* youngs : {"\"200 GPa\"", "\"2 GPa\""}) {
      const std::vector<std::string> set = {std::string("particles.density=") + density,
                                            std::string("contact.youngs_modulus=") + youngs,
                                            "numerics.integrator=auto"};
      expect_auto_rule(scene(set), set[0] + " " + set[1]);
    }
}

// Above the Stokes bound the particles keep their inertia even where the
// implicit scheme's step bound is many times the explicit one (iron's
// modulus), which would otherwise choose it.
TEST(RunIntegratorChoice, AutoKeepsInertiaAboveTheStokesBound) {
  for (const char* mason : {"0.003", "0.01"}) {
    const LoadedScene s = scene({"particles.density=78000", std::string("drive.mason=") + mason,
                                 "contact.youngs_modulus=\"200 GPa\"", "numerics.integrator=auto"});
    const DemParams p = dem_params(s.config);
    ASSERT_GT(stokes_number(p), k_inertialess_max_stokes) << mason;
    EXPECT_GT(smallest(dem_limits(p, s.config.gap, IntegratorId::implicit)),
              k_implicit_preference * smallest(dem_limits(p, s.config.gap, IntegratorId::verlet_exp)));
    EXPECT_EQ(choose_time_step(s, p).scheme, IntegratorId::verlet_exp) << mason;
  }
}

TEST(RunIntegratorChoice, TinyDensityRunReportsTheSchemeOfTheRule) {
  const std::vector<std::string> set = {"particles.density=7.8", "contact.youngs_modulus=\"0.45 GPa\"",
                                        "numerics.integrator=auto", "drive.mason=0.1",
                                        "drive.strain=0.5", "drive.warmup_strain=0.1",
                                        "output.every=0"};
  const LoadedScene s = scene(set);
  const DemParams p = dem_params(s.config);
  const auto ve = dem_limits(p, s.config.gap, IntegratorId::verlet_exp);
  const auto od = dem_limits(p, s.config.gap, IntegratorId::overdamped);
  const bool ve_wins = smallest(ve) >= smallest(od);
  const RunSummary r = run_scene(s, RunOptions{"", true});
  EXPECT_EQ(r.integrator, ve_wins ? "verlet_exp" : "overdamped");
  EXPECT_EQ(r.binding_limit, binding(ve_wins ? ve : od).name);
  EXPECT_EQ(r.binding_limit, "hertz contact");
  // St << 1 here: the two contact limits nearly coincide (the exponential
  // integrator tends to explicit overdamped Euler as tau_p -> 0).
  EXPECT_LT(r.stokes_number, 1e-4);
  EXPECT_LT(rel(smallest(ve), smallest(od)), 1e-3);
  RecordProperty("verlet_exp_limit_s", g17(smallest(ve)));
  RecordProperty("overdamped_limit_s", g17(smallest(od)));
}

}  // namespace
}  // namespace mrf
