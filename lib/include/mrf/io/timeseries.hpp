// A run's timeseries.csv read back, and the averaging window the run took
// from it: for re-estimating a finished run's statistics with the current
// block_average (`mrf reanalyse`) when the estimator has changed since.
#pragma once
#include <string>
#include <vector>

#include "mrf/observe/block_average.hpp"

namespace mrf {

struct TimeSeriesTable {
  std::vector<std::string> names;               // the header's columns
  std::vector<std::vector<double>> columns;     // per column, one value per row
  // the column of that name; throws InputError naming the file's columns if absent
  const std::vector<double>& column(const std::string& name) const;
  std::string path;
};

// Throws InputError (file and line) on a row with another number of fields
// than the header or a field that is not a number.
TimeSeriesTable read_timeseries(const std::string& path);

// The rows the run averaged (run.cpp): those that start at or after the
// warm-up, a row starting where the one before it ended (strain 0 for the
// first). The strain column is written to 10 significant digits, so a row
// that starts within 1e-9 of the warm-up's end may be taken where the run
// did not take it.
std::vector<double> averaging_window(const TimeSeriesTable& t, const std::string& column, double warmup_strain);

// The columns a re-analysis reads (reanalyse_run), and the rows it can
// read them from: the time series' averaging window for `warmup_strain`,
// preceded by the last warm-up row (whose end is where the window starts),
// those columns only, each field as the file wrote it. The sweep archive
// keeps this beside a point's summary.json (window_series.csv, a few
// hundred kB at most), so that a later estimator can be applied to runs
// whose output folder is gone. Throws InputError (file, line) as
// read_timeseries does.
inline const char* const k_window_series_file = "window_series.csv";
std::string window_series_text(const std::string& timeseries_path, double warmup_strain);

// The statistics of the named measurements of a finished run (directory
// with summary.json and timeseries.csv, or an archive entry with
// summary.json and window_series.csv) by the current estimator, as JSON:
// per measurement mean, err, drift_z, independent_samples, and beside
// them what summary.json holds (`stored_*`, and the summary's
// error_estimate_version, 1 when absent). Measurements: stress_total,
// stress_particles, stress_virial (magnetic + contact); and the MSER-5
// discard fraction of the total, the policy's other steadiness test.
std::string reanalyse_run(const std::string& dir);

}  // namespace mrf
