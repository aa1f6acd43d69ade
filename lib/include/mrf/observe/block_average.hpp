// Mean and standard error of a correlated time series by block averaging
// (Flyvbjerg & Petersen 1989; level chosen by Jonsson 2018), with a drift
// check of the averaging window.
#pragma once
#include <vector>

namespace mrf {

struct BlockAverage {
  double mean = 0;
  double sem = 0;        // standard error of the mean, automatic blocking (Jonsson 2018)
  int samples = 0;
  double half_difference = 0;  // mean(second half) - mean(first half)
  double drift_z = 0;          // half_difference / its standard error; |z| > 3 flags drift
};

BlockAverage block_average(const std::vector<double>& series);

}  // namespace mrf
