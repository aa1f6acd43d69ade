// `mrf sweep`: the grid, its overrides, the split across ranks, resuming a
// killed sweep, and sweep.csv (issue 6).
#include "mrf/study/sweep.hpp"

#include <gtest/gtest.h>

#include <limits>

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/study/criterion.hpp"

namespace mrf {
namespace {

const std::string k_scenes = MRF_SOURCE_DIR "/experiments/scenes";

std::string grid_text(const std::string& extra = "") {
  return "[sweep]\n"
         "scene = \"small_dem_stokes.toml\"\n"
         "models = [\"dem_stokes\", \"demsph_dd\"]\n"
         "mason = [1e-3, 0.01, 1.0]\n"
         "seeds = [1, 2]\n"
         "set = [\"drive.strain=4\"]\n" +
         extra;
}

// The realistic path (REFERENCE §8): the sweep holds the shear rate and the
// Mason number of each point sets the magnetisation.
TEST(Sweep, MasonNumberByMagnetizationAtAFixedShearRate) {
  const SweepSpec s = parse_sweep("[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\n"
                                  "mason = [1e-3, 0.01, 1.0]\nseeds = [1]\n"
                                  "set = [\"drive.vary='magnetization'\", \"drive.shear_rate=1e3\"]\n",
                                  "grid.toml", k_scenes);
  double last_m = std::numeric_limits<double>::infinity();
  for (const SweepPoint& p : sweep_points(s)) {
    const LoadedScene scene = load_scene(s.scene_path, p.sets);
    EXPECT_DOUBLE_EQ(scene.config.shear_rate, 1e3);
    EXPECT_DOUBLE_EQ(scene.config.mason, p.mason);
    EXPECT_LT(scene.config.magnetization, last_m);  // weaker fields reach higher Mn
    last_m = scene.config.magnetization;
  }
}

TEST(Sweep, GridIsModelMajorWithOverridesInOrder) {
  const SweepSpec s = parse_sweep(grid_text("[[rule]]\nmason_max = 2e-3\nmodels = [\"dem_stokes\"]\n"
                                            "set = [\"drive.strain=2\"]\n"),
                                  "grid.toml", k_scenes);
  const auto pts = sweep_points(s);
  ASSERT_EQ(pts.size(), 2u * 3u * 2u);
  EXPECT_EQ(pts[0].model, "dem_stokes");
  EXPECT_EQ(pts[0].mason, 1e-3);
  EXPECT_EQ(pts[1].seed, 2u);
  EXPECT_EQ(pts[2].mason, 0.01);
  EXPECT_EQ(pts[6].model, "demsph_dd");
  EXPECT_EQ(pts[3].dir, "dem_stokes/mn_0.01_seed_2");
  // the rule applies to dem_stokes at Mn <= 2e-3 only, after the sweep-wide set
  const std::vector<std::string> first{"drive.strain=4", "drive.strain=2", "scene.model=\"dem_stokes\"",
                                       "drive.mason=0.001", "scene.seed=1"};
  EXPECT_EQ(pts[0].sets, first);
  EXPECT_EQ(pts[2].sets.size(), 4u);
  EXPECT_EQ(pts[6].sets.size(), 4u);  // demsph_dd at 1e-3: rule does not match the model
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(pts[i].index, i);
}

void expect_input_error(const std::string& text, const std::string& key, const std::string& where) {
  try {
    parse_sweep(text, "grid.toml", k_scenes);
    FAIL() << "expected InputError for " << key;
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
  }
}

TEST(Sweep, BadInputNamesKeyAndLine) {
  expect_input_error(grid_text("bogus = 1\n"), "sweep.bogus", "grid.toml:7");
  expect_input_error(grid_text("[extra]\nx = 1\n"), "extra", "grid.toml:7");
  std::string t = grid_text();
  expect_input_error(t.replace(t.find("demsph_dd"), 9, "demsph_xx"), "sweep.models", "grid.toml:3");
  t = grid_text();
  expect_input_error(t.replace(t.find("1e-3"), 4, "-1e-3"), "sweep.mason", "grid.toml:4");
  t = grid_text();
  expect_input_error(t.replace(t.find("small_dem"), 9, "nothere_x"), "sweep.scene", "grid.toml:2");
  expect_input_error(grid_text("[[rule]]\nmason_max = 1.0\n"), "rule.set", "grid.toml:7");
  expect_input_error(grid_text("[[rule]]\nspeed = 1.0\nset = [\"a.b=1\"]\n"), "rule.speed", "grid.toml:8");
}

TEST(Sweep, RanksShareThePointsExactlyOnce) {
  for (int size : {1, 2, 3, 7}) {
    std::multiset<std::size_t> all;
    for (int r = 0; r < size; ++r)
      for (std::size_t i : points_of_rank(12, r, size)) all.insert(i);
    ASSERT_EQ(all.size(), 12u) << size;
    for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(all.count(i), 1u) << size;
  }
  EXPECT_THROW(points_of_rank(12, 2, 2), std::invalid_argument);
}

TEST(Sweep, RankFromOpenMpiEnvironment) {
  ::setenv("OMPI_COMM_WORLD_RANK", "2", 1);
  ::setenv("OMPI_COMM_WORLD_SIZE", "3", 1);
  const RankInfo r = rank_from_environment();
  EXPECT_EQ(r.rank, 2);
  EXPECT_EQ(r.size, 3);
  ::unsetenv("OMPI_COMM_WORLD_RANK");
  ::unsetenv("OMPI_COMM_WORLD_SIZE");
  const RankInfo none = rank_from_environment();
  EXPECT_EQ(none.rank, 0);
  EXPECT_EQ(none.size, 1);
}

nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

// A short two-point sweep; "killing" it leaves one point without summary.json
// (and a stale temporary file); the resumed sweep runs exactly that point and
// reproduces it bit for bit.
TEST(Sweep, KilledSweepResumesAndReproduces) {
  const auto out = std::filesystem::temp_directory_path() / "mrf_test_sweep";
  std::filesystem::remove_all(out);
  const SweepSpec s = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [0.3, 1.0]\nseeds = [3]\n"
      "set = [\"drive.strain=0.6\", \"drive.warmup_strain=0.2\"]\n",
      "tiny.toml", k_scenes);
  SweepOptions opt;
  opt.quiet = true;
  const SweepOutcome first = run_sweep(s, out.string(), opt);
  EXPECT_EQ(first.ran, 2u);
  EXPECT_EQ(first.failed, 0u);
  const auto p1 = out / "dem_stokes/mn_1_seed_3";
  const double stress = read_json(p1 / "summary.json")["stress_total"].get<double>();
  std::filesystem::remove(p1 / "summary.json");
  std::ofstream(p1 / "summary.json.tmp") << "{ \"half";
  const SweepOutcome second = run_sweep(s, out.string(), opt);
  EXPECT_EQ(second.ran, 1u);
  EXPECT_EQ(second.skipped, 1u);
  EXPECT_EQ(read_json(p1 / "summary.json")["stress_total"].get<double>(), stress);
  std::ifstream csv(out / "sweep.csv");
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("model,mason,seed,status,shear_rate", 0), 0u) << header;
  int rows = 0;
  while (std::getline(csv, row)) {
    ++rows;
    EXPECT_NE(row.find(",ok,"), std::string::npos) << row;
  }
  EXPECT_EQ(rows, 2);
  const SweepOutcome third = run_sweep(s, out.string(), opt);
  EXPECT_EQ(third.ran, 0u);
  EXPECT_EQ(third.skipped, 2u);

  // Estimates calibrated by the finished points: a finished point its own
  // wall time; a new Mn of the same model the nearest finished point's
  // seconds per strain unit times its strain.
  const SweepSpec wider = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [0.3, 1.0, 3.0]\nseeds = [3]\n"
      "set = [\"drive.strain=0.6\", \"drive.warmup_strain=0.2\"]\n",
      "tiny.toml", k_scenes);
  const auto pts = sweep_points(wider);
  const PointEstimates est = estimate_points(wider, pts, out.string(), 1e6);
  ASSERT_EQ(est.seconds.size(), 3u);
  EXPECT_TRUE(est.calibrated[0] && est.calibrated[1] && est.calibrated[2]);
  EXPECT_EQ(est.seconds[1], read_json(p1 / "summary.json")["wall_seconds"].get<double>());
  EXPECT_DOUBLE_EQ(est.seconds[2], read_json(p1 / "summary.json")["seconds_per_strain"].get<double>() * 0.6);
  const PointEstimates fresh = estimate_points(wider, pts, (out / "nothing_here").string(), 1e6);
  EXPECT_FALSE(fresh.calibrated[2]);
  // An empty out_dir beside an archive of finished points (what `--point K
  // --archive DIR` sees on a new machine): calibrated by the archive's
  // seconds per strain unit, the point's own entry first.
  const PointEstimates archived = estimate_points(wider, pts, (out / "nothing_here").string(), 1e6, out.string());
  EXPECT_TRUE(archived.calibrated[1] && archived.calibrated[2]);
  EXPECT_DOUBLE_EQ(archived.seconds[1], read_json(p1 / "summary.json")["seconds_per_strain"].get<double>() * 0.6);
  // --calibrate-from: the same folder read for the cost alone (a fresh run
  // estimated from an earlier one's measured cost) gives the same estimates;
  // the archive, where it has the point, comes first.
  const PointEstimates calibrated =
      estimate_points(wider, pts, (out / "nothing_here").string(), 1e6, "", {out.string()});
  EXPECT_TRUE(calibrated.calibrated[1] && calibrated.calibrated[2]);
  EXPECT_DOUBLE_EQ(calibrated.seconds[1], archived.seconds[1]);
  EXPECT_DOUBLE_EQ(calibrated.seconds[2], archived.seconds[2]);
  const PointEstimates both =
      estimate_points(wider, pts, (out / "nothing_here").string(), 1e6, out.string(), {(out / "nothing_here").string()});
  EXPECT_DOUBLE_EQ(both.seconds[1], archived.seconds[1]);
  // --calibrate-from given twice: a folder without the point is passed over
  const PointEstimates two_folders = estimate_points(wider, pts, (out / "nothing_here").string(), 1e6, "",
                                                     {(out / "nothing_here").string(), out.string()});
  EXPECT_TRUE(two_folders.calibrated[1]);
  EXPECT_DOUBLE_EQ(two_folders.seconds[1], archived.seconds[1]);
  // A sweep with --calibrate-from runs its points: nothing is restored from
  // the calibration folder; its seconds per strain unit give the estimate.
  SweepOptions cal = opt;
  cal.calibrate = {out.string()};
  const auto fresh_out = std::filesystem::temp_directory_path() / "mrf_test_sweep_calibrated";
  std::filesystem::remove_all(fresh_out);
  // a variant sweep calibrated by a plain one: the same model, Mn and seed
  const SweepSpec with_variant = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [1.0]\nseeds = [3]\n"
      "set = [\"drive.strain=0.6\", \"drive.warmup_strain=0.2\"]\n[[variant]]\nname = \"stiff\"\n"
      "set = [\"contact.youngs_modulus=4e10\"]\n",
      "tiny.toml", k_scenes);
  const PointEstimates by_plain = estimate_points(with_variant, sweep_points(with_variant),
                                                  (out / "nothing_here").string(), 1e6, "", {out.string()});
  ASSERT_TRUE(by_plain.calibrated[0]);
  EXPECT_DOUBLE_EQ(by_plain.seconds[0], read_json(p1 / "summary.json")["seconds_per_strain"].get<double>() * 0.6);
  // more seeds of a finished point (none of them run yet): calibrated by the
  // same model and Mn at another seed in the calibration folder, not by the
  // particle-steps model; a Mn the folder lacks, by those (the nearest Mn)
  const SweepSpec more_seeds = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [1.0, 2.0]\nseeds = [7, 8]\n"
      "set = [\"drive.strain=0.9\", \"drive.warmup_strain=0.3\"]\n",
      "tiny.toml", k_scenes);
  const PointEstimates by_seed = estimate_points(more_seeds, sweep_points(more_seeds), (out / "nothing_here").string(),
                                                 1e6, "", {out.string()});
  for (std::size_t k = 0; k < 4; ++k) {  // Mn 1 and 2, seeds 7 and 8
    ASSERT_TRUE(by_seed.calibrated[k]);
    EXPECT_DOUBLE_EQ(by_seed.seconds[k], read_json(p1 / "summary.json")["seconds_per_strain"].get<double>() * 0.9);
  }
  const SweepSpec short_one = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [1.0]\nseeds = [3]\n"
      "set = [\"drive.strain=0.6\", \"drive.warmup_strain=0.2\"]\n",
      "tiny.toml", k_scenes);
  const SweepOutcome calibrated_run = run_sweep(short_one, fresh_out.string(), cal);
  EXPECT_EQ(calibrated_run.ran, 1u);
  EXPECT_EQ(calibrated_run.skipped, 0u);
  EXPECT_NEAR(calibrated_run.estimated_seconds, read_json(p1 / "summary.json")["seconds_per_strain"].get<double>() * 0.6,
              1e-9);
  std::filesystem::remove_all(fresh_out);

  // `--point K` (what a job array hands out) runs point K alone, into the
  // same folder with the same result; a K outside the grid is refused.
  const auto alone = std::filesystem::temp_directory_path() / "mrf_test_sweep_point";
  std::filesystem::remove_all(alone);
  SweepOptions one = opt;
  one.point = 1;
  const SweepOutcome fourth = run_sweep(s, alone.string(), one);
  EXPECT_EQ(fourth.ran, 1u);
  EXPECT_FALSE(std::filesystem::exists(alone / "dem_stokes/mn_0.3_seed_3"));
  EXPECT_EQ(read_json(alone / "dem_stokes/mn_1_seed_3" / "summary.json")["stress_total"].get<double>(), stress);
  one.point = 2;
  EXPECT_THROW(run_sweep(s, alone.string(), one), InputError);
  std::filesystem::remove_all(alone);

  // A full disk at the second point (its time series goes to /dev/full):
  // the sweep stops with an OutputError, the first point stays finished and
  // the second resumable (no failure.json, which would mark it done).
  if (std::filesystem::exists("/dev/full")) {
    const auto full = std::filesystem::temp_directory_path() / "mrf_test_sweep_full";
    std::filesystem::remove_all(full);
    std::filesystem::create_directories(full / "dem_stokes/mn_1_seed_3");
    std::filesystem::create_symlink("/dev/full", full / "dem_stokes/mn_1_seed_3/timeseries.csv");
    EXPECT_THROW(run_sweep(s, full.string(), opt), OutputError);
    EXPECT_TRUE(point_finished((full / "dem_stokes/mn_0.3_seed_3").string()));
    EXPECT_FALSE(std::filesystem::exists(full / "dem_stokes/mn_1_seed_3/failure.json"));
    EXPECT_FALSE(point_finished((full / "dem_stokes/mn_1_seed_3").string()));
    std::filesystem::remove_all(full);
  }
}

}  // namespace
}  // namespace mrf

namespace mrf {
namespace {

// Each point's summary.json as its scene states it before a run (no run),
// under `out`, which is emptied first.
void write_point_summaries(const SweepSpec& s, const std::vector<SweepPoint>& pts, const std::filesystem::path& out) {
  std::filesystem::remove_all(out);
  for (const auto& p : pts) {
    const LoadedScene scene = load_scene(s.scene_path, p.sets);
    std::filesystem::create_directories(out / p.dir);
    std::ofstream(out / p.dir / "summary.json") << summary_json(scene_summary(scene.config));
  }
}

// summary.json -> sweep.csv -> the criterion's table: the carrier viscosity
// and density travel with every point, so a sweep of the SPH models alone
// has them (the criterion used to rebuild eta from a model-1 row).
TEST(Sweep, SweepCsvCarriesTheFluidViscosityAndDensity) {
  const auto out = std::filesystem::temp_directory_path() / "mrf_test_sweep_fluid";
  const SweepSpec s = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"demsph_dd\"]\nmason = [0.1]\nseeds = [1]\n"
      "set = [\"fluid.viscosity=0.25\", \"fluid.density=960\"]\n",
      "fluid.toml", k_scenes);
  const auto pts = sweep_points(s);
  ASSERT_EQ(pts.size(), 1u);
  write_point_summaries(s, pts, out);
  const std::string csv = sweep_csv(pts, out.string());
  std::ofstream(out / "sweep.csv") << csv;
  const SweepTable t = read_sweep_csv((out / "sweep.csv").string());
  EXPECT_EQ(t.viscosity, 0.25) << csv;
  EXPECT_EQ(t.fluid_density, 960) << csv;
  EXPECT_TRUE(t.viscosity_note.empty()) << t.viscosity_note;
}

// A Mason number with more digits than the folder label: the point's scene,
// its summary.json and sweep.csv all hold the sweep file's value bit for bit
// (the override used to be the 4-digit label, 0.01235 for 0.0123456789).
TEST(Sweep, PointSceneAndSweepCsvHoldTheExactMasonNumber) {
  const auto out = std::filesystem::temp_directory_path() / "mrf_test_sweep_mason";
  const SweepSpec s = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\n"
      "mason = [0.0123456789, 0.1, 3.3333333333333335e-5]\nseeds = [1]\n",
      "mason.toml", k_scenes);
  const auto pts = sweep_points(s);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[0].mason, 0.0123456789);
  EXPECT_EQ(pts[0].dir, "dem_stokes/mn_0.01235_seed_1");  // folder names keep 4 digits
  for (const auto& p : pts) {
    const LoadedScene scene = load_scene(s.scene_path, p.sets);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(scene.config.mason), std::bit_cast<std::uint64_t>(p.mason))
        << p.dir << ": " << scene.config.mason << " != " << p.mason;
  }
  write_point_summaries(s, pts, out);
  std::istringstream csv(sweep_csv(pts, out.string()));
  std::string line;
  std::getline(csv, line);
  for (const auto& p : pts) {
    ASSERT_TRUE(std::getline(csv, line));
    const std::string cell = line.substr(line.find(',') + 1, line.find(',', line.find(',') + 1) - line.find(',') - 1);
    const double in_csv = std::strtod(cell.c_str(), nullptr);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(in_csv), std::bit_cast<std::uint64_t>(p.mason)) << line;
    std::ifstream in(out / p.dir / "summary.json");
    const double in_summary = nlohmann::json::parse(in)["mason"].get<double>();
    EXPECT_EQ(std::bit_cast<std::uint64_t>(in_summary), std::bit_cast<std::uint64_t>(in_csv)) << line;
  }
}

// An SPH spacing that does not divide the gap (80 um / 6 um) is refused for
// the demsph_dd point before any point runs (it used to fail only when the
// sweep reached it, after the dem_stokes point had run), naming the point,
// the key, where it was set and the value.
TEST(Sweep, CoupledPointWithABadSphSpacingStopsTheSweepBeforeAnyRun) {
  const auto out = std::filesystem::temp_directory_path() / "mrf_test_sweep_sph";
  std::filesystem::remove_all(out);
  const SweepSpec s = parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\", \"demsph_dd\"]\nmason = [0.1]\n"
      "seeds = [1]\nset = [\"drive.strain=0.5\", \"drive.warmup_strain=0.1\", \"fluid.sph_spacing=6e-6\"]\n",
      "sph.toml", k_scenes);
  SweepOptions opt;
  opt.quiet = true;
  try {
    run_sweep(s, out.string(), opt);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.key(), "fluid.sph_spacing") << msg;
    for (const char* part : {"demsph_dd/mn_0.1_seed_1", "--set fluid.sph_spacing=6e-6", "6e-06", "box.gap"})
      EXPECT_NE(msg.find(part), std::string::npos) << part << " not in: " << msg;
  }
  EXPECT_FALSE(std::filesystem::exists(out / "dem_stokes")) << "a point ran before the check";
}

TEST(Sweep, FailedPointCountsAsFinishedUntilItsFolderIsDeleted) {
  const auto d = std::filesystem::temp_directory_path() / "mrf_test_point";
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  EXPECT_FALSE(point_finished(d.string()));
  std::ofstream(d / "summary.json.tmp") << "{";
  EXPECT_FALSE(point_finished(d.string()));  // a half-written summary does not count
  std::ofstream(d / "failure.json") << "{}";
  EXPECT_TRUE(point_finished(d.string()));
}

}  // namespace
}  // namespace mrf
