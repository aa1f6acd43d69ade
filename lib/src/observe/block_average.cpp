#include "mrf/observe/block_average.hpp"

#include <gsl/gsl_cdf.h>

#include <cmath>
#include <numeric>

namespace mrf {

namespace {

// Mean as first value plus the mean deviation: exact for a constant series.
double mean_of(const double* a, std::size_t n) {
  if (n == 0) return 0.0;
  double dev = 0;
  for (std::size_t i = 0; i < n; ++i) dev += a[i] - a[0];
  return a[0] + dev / static_cast<double>(n);
}

// Automatic blocking (Jonsson, Phys. Rev. E 98, 043304, 2018) on the last
// 2^d samples: at each blocking level k, with n_k blocks, biased variance
// s_k^2 and lag-one autocovariance g_k, the statistic
//   M_j = sum_{k>=j} n_k ((n_k - 1) s_k^2 / n_k^2 + g_k)^2 / s_k^4
// is chi-square with d - j degrees of freedom once the blocks are
// uncorrelated; the first level where M_j falls below the 99 % quantile
// gives sem^2 = s_j^2 / n_j.
double blocked_sem(const double* a, std::size_t n) {
  if (n < 2) return 0.0;
  int d = 0;
  while ((std::size_t{2} << d) <= n) ++d;  // 2^d <= n
  std::vector<double> x(a + (n - (std::size_t{1} << d)), a + n);
  std::vector<double> s2(d), g(d), nk(d);
  for (int k = 0; k < d; ++k) {
    const double m = mean_of(x.data(), x.size());
    double v = 0, c = 0;
    for (std::size_t i = 0; i < x.size(); ++i) v += (x[i] - m) * (x[i] - m);
    for (std::size_t i = 0; i + 1 < x.size(); ++i) c += (x[i] - m) * (x[i + 1] - m);
    nk[k] = static_cast<double>(x.size());
    s2[k] = v / nk[k];
    g[k] = c / nk[k];
    for (std::size_t i = 0; i < x.size() / 2; ++i) x[i] = 0.5 * (x[2 * i] + x[2 * i + 1]);
    x.resize(x.size() / 2);
  }
  if (s2[0] == 0.0) return 0.0;
  std::vector<double> m_stat(d + 1, 0.0);
  for (int k = d - 1; k >= 0; --k) {
    const double t = (nk[k] - 1) * s2[k] / (nk[k] * nk[k]) + g[k];
    m_stat[k] = m_stat[k + 1] + (s2[k] > 0 ? nk[k] * t * t / (s2[k] * s2[k]) : 0.0);
  }
  int level = d - 1;
  for (int j = 0; j < d; ++j)
    if (m_stat[j] < gsl_cdf_chisq_Pinv(0.99, d - j)) {
      level = j;
      break;
    }
  return std::sqrt(s2[level] / nk[level]);
}

}  // namespace

BlockAverage block_average(const std::vector<double>& series) {
  BlockAverage r;
  const std::size_t n = series.size();
  r.samples = static_cast<int>(n);
  r.mean = mean_of(series.data(), n);
  r.sem = blocked_sem(series.data(), n);
  const std::size_t h = n / 2;
  if (h >= 8) {
    const double* first = series.data();
    const double* second = series.data() + (n - h);
    r.half_difference = mean_of(second, h) - mean_of(first, h);
    const double e = std::hypot(blocked_sem(first, h), blocked_sem(second, h));
    r.drift_z = e > 0 ? r.half_difference / e : 0.0;
  }
  return r;
}

}  // namespace mrf
