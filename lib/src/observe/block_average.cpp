#include "mrf/observe/block_average.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace mrf {

namespace {
double mean_of(const std::vector<double>& a) {
  return a.empty() ? 0.0 : std::accumulate(a.begin(), a.end(), 0.0) / static_cast<double>(a.size());
}

// Blocking transformation: SEM of the naive estimator at each level while at
// least 8 blocks remain; correlated data make it rise to a plateau. The
// largest value is taken (conservative when the plateau is not reached).
double blocked_sem(std::vector<double> a) {
  double best = 0;
  while (a.size() >= 8) {
    const double m = mean_of(a);
    double var = 0;
    for (double v : a) var += (v - m) * (v - m);
    const double n = static_cast<double>(a.size());
    best = std::max(best, std::sqrt(var / (n * (n - 1))));
    std::vector<double> b(a.size() / 2);
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = 0.5 * (a[2 * i] + a[2 * i + 1]);
    a.swap(b);
  }
  return best;
}
}  // namespace

BlockAverage block_average(const std::vector<double>& series) {
  BlockAverage r;
  r.samples = static_cast<int>(series.size());
  r.mean = mean_of(series);
  r.sem = blocked_sem(series);
  const std::size_t h = series.size() / 2;
  if (h >= 8) {
    const std::vector<double> first(series.begin(), series.begin() + static_cast<long>(h));
    const std::vector<double> second(series.end() - static_cast<long>(h), series.end());
    r.half_difference = mean_of(second) - mean_of(first);
    const double e = std::hypot(blocked_sem(first), blocked_sem(second));
    r.drift_z = e > 0 ? r.half_difference / e : 0.0;
  }
  return r;
}

}  // namespace mrf
