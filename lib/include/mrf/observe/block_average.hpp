// Mean and standard error of a correlated time series by block averaging
// (Flyvbjerg & Petersen 1989; level chosen by Jonsson 2018), with a drift
// check of the averaging window.
#pragma once
#include <vector>

namespace mrf {

struct BlockAverage {
  double mean = 0;
  double sem = 0;        // standard error of the mean, automatic blocking (Jonsson 2018), widened
                         // by the residual correlation of the chosen blocks (block_average.cpp)
  int samples = 0;
  // Var(x) / sem^2: how many independent samples the series is worth (the
  // samples over the statistical inefficiency); few (tens) mean the error
  // and the drift test rest on few correlation times. 0 for a constant series.
  double independent_samples = 0;
  double half_difference = 0;  // mean(second half) - mean(first half)
  double drift_z = 0;          // half_difference / its standard error (each half's from the half with
                               // its least-squares line removed); |z| > 3 flags drift
};

BlockAverage block_average(const std::vector<double>& series);

// Which estimate of `sem` and `drift_z` a run's summary.json carries
// (`error_estimate_version`; absent in older summaries = 1): 1, Jonsson's
// level alone; 2, widened by the chosen blocks' lag-one correlation, and
// the drift test's errors from the detrended halves (docs/study.md, "Error
// bars with few correlation times").
inline constexpr int k_error_estimate_version = 2;

}  // namespace mrf
