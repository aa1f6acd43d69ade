// A run's timeseries.csv read back (io/timeseries.hpp): re-estimating a
// fresh run's statistics from its file gives what its summary.json holds
// (the same estimator, the same window, values to the file's 10 digits),
// and a damaged file is refused with its line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mrf/error.hpp"
#include "mrf/io/timeseries.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

TEST(TimeSeries, ReanalysingAFreshRunGivesItsSummary) {
  const auto dir = std::filesystem::temp_directory_path() / "mrf_reanalyse";
  std::filesystem::remove_all(dir);
  RunOptions opt;
  opt.out_dir = dir.string();
  opt.quiet = true;
  opt.checkpoint_seconds = 0;
  const RunSummary s = run_scene(load_scene(MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml",
                                            {"drive.mason=0.1", "drive.strain=0.6", "drive.warmup_strain=0.2"}),
                                 opt);
  const nlohmann::json r = nlohmann::json::parse(reanalyse_run(dir.string()));
  EXPECT_EQ(r["stored_error_estimate_version"].get<int>(), k_error_estimate_version);
  EXPECT_EQ(r["steady_mser_discard_fraction"].get<double>(), s.extra.at("steady_mser_discard_fraction"));
  struct Case {
    const char* key;
    Measurement m;
  };
  for (const Case& c : {Case{"stress_total", s.stress_total}, Case{"stress_particles", s.stress_particles},
                        Case{"stress_virial", s.stress_virial}}) {
    const auto& q = r[c.key];
    EXPECT_NEAR(q["mean"].get<double>(), c.m.mean, 1e-8 * std::abs(c.m.mean)) << c.key;
    EXPECT_NEAR(q["err"].get<double>(), c.m.err, 1e-6 * c.m.err) << c.key;
    EXPECT_NEAR(q["drift_z"].get<double>(), c.m.drift_z, 1e-5 * (1 + std::abs(c.m.drift_z))) << c.key;
    EXPECT_NEAR(q["independent_samples"].get<double>(), c.m.independent_samples,
                1e-5 * c.m.independent_samples) << c.key;
    EXPECT_EQ(q["stored_mean"].get<double>(), c.m.mean) << c.key;
    EXPECT_GT(q["samples"].get<int>(), 32) << c.key;
  }

  // The archive keeps only the window (and the row before it) of the
  // columns a re-analysis reads: the same statistics from it.
  const auto kept = std::filesystem::temp_directory_path() / "mrf_reanalyse_archived";
  std::filesystem::remove_all(kept);
  std::filesystem::create_directories(kept);
  std::filesystem::copy_file(dir / "summary.json", kept / "summary.json");
  const std::string text = window_series_text((dir / "timeseries.csv").string(), 0.2);
  std::ofstream(kept / k_window_series_file) << text;
  nlohmann::json a = nlohmann::json::parse(reanalyse_run(kept.string()));
  nlohmann::json b = r;
  a.erase("dir");
  b.erase("dir");
  EXPECT_EQ(a, b);
  const TimeSeriesTable w = read_timeseries((kept / k_window_series_file).string());
  const TimeSeriesTable full = read_timeseries((dir / "timeseries.csv").string());
  EXPECT_EQ(w.column("strain").size(), r["stress_total"]["samples"].get<std::size_t>() + 1);
  // its first row is the last warm-up row: it starts before 0.2 (where the
  // row before it in the full file ends)
  const std::size_t first = full.column("strain").size() - w.column("strain").size();
  ASSERT_GT(first, 0u);
  EXPECT_LT(full.column("strain")[first - 1], 0.2);
  EXPECT_GE(w.column("strain").front(), 0.2);
  EXPECT_LT(w.names.size(), full.names.size());  // energies and overlaps left out
  EXPECT_EQ(w.column("stress_total_Pa").back(), full.column("stress_total_Pa").back());
}

TEST(TimeSeries, DamagedFileNamesItsLine) {
  const auto p = std::filesystem::temp_directory_path() / "mrf_bad_timeseries.csv";
  {
    std::ofstream f(p);
    f << "time_s,strain,stress_total_Pa\n1,0.1,5\n2,0.2,x7\n";
  }
  try {
    read_timeseries(p.string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string() + ":3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("x7"), std::string::npos) << e.what();
  }
  {
    std::ofstream f(p);
    f << "time_s,strain,stress_total_Pa\n1,0.1\n";
  }
  EXPECT_THROW(read_timeseries(p.string()), InputError);
  {
    std::ofstream f(p);
    f << "time_s,strain,stress_total_Pa\n1,0.1,5\n";
  }
  const TimeSeriesTable t = read_timeseries(p.string());
  try {
    (void)t.column("stress_particles_Pa");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stress_total_Pa"), std::string::npos) << e.what();
  }
}

TEST(TimeSeries, WindowStartsWithTheFirstRowAfterTheWarmup) {
  TimeSeriesTable t;
  t.names = {"strain", "v"};
  t.columns = {{0.1, 0.2, 0.3, 0.4}, {1, 2, 3, 4}};
  // rows start at 0, 0.1, 0.2, 0.3: warm-up 0.2 keeps the rows starting at 0.2 and 0.3
  EXPECT_EQ(averaging_window(t, "v", 0.2), (std::vector<double>{3, 4}));
  EXPECT_EQ(averaging_window(t, "v", 0.0), (std::vector<double>{1, 2, 3, 4}));
}

}  // namespace
}  // namespace mrf
