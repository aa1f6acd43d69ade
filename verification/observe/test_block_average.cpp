// Block averaging (observe/block_average): the standard error of the mean of
// white noise and of an AR(1) series against their closed forms, a constant
// series, and the drift check (a linear trend is flagged, pure noise is not),
// also with only a few correlation times in the series.
//
// Normal deviates come from std::mt19937_64 (its output is fixed by the
// standard) through Box-Muller, so every platform sees the same series.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "mrf/observe/block_average.hpp"

namespace mrf {
namespace {

class Normal {
 public:
  explicit Normal(std::uint64_t seed) : g_(seed) {}
  double operator()() {
    if (have_) {
      have_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform(), u2 = uniform();  // u1 in (0, 1]
    const double r = std::sqrt(-2.0 * std::log(u1)), t = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(t);
    have_ = true;
    return r * std::cos(t);
  }

 private:
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }
  std::mt19937_64 g_;
  double spare_ = 0;
  bool have_ = false;
};

std::vector<double> white_noise(std::size_t n, double mean, double sigma, std::uint64_t seed) {
  Normal z(seed);
  std::vector<double> x(n);
  for (double& v : x) v = mean + sigma * z();
  return x;
}

// Stationary AR(1): x_i = rho x_{i-1} + e_i with Var(x) = sigma_x^2.
std::vector<double> ar1(std::size_t n, double rho, double sigma_x, std::uint64_t seed) {
  Normal z(seed);
  const double sigma_e = sigma_x * std::sqrt(1.0 - rho * rho);
  std::vector<double> x(n);
  double y = sigma_x * z();
  for (double& v : x) {
    v = y;
    y = rho * y + sigma_e * z();
  }
  return x;
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// The estimator is checked on its average over many independent series: one
// series carries the estimator's own scatter (about 27 % at 8 blocks).
TEST(BlockAverage, WhiteNoiseSemIsSigmaOverRootN) {
  constexpr std::size_t n = 1 << 14;
  constexpr double sigma = 2.0, mu = 5.0;
  constexpr int repeats = 64;
  const double exact = sigma / std::sqrt(static_cast<double>(n));
  std::vector<double> ratio, independent;
  int within = 0;
  for (int s = 0; s < repeats; ++s) {
    const BlockAverage b = block_average(white_noise(n, mu, sigma, 1000 + s));
    EXPECT_EQ(b.samples, static_cast<int>(n));
    EXPECT_LT(std::abs(b.mean - mu), 5 * exact) << "seed " << s;
    ratio.push_back(b.sem / exact);
    independent.push_back(b.independent_samples / static_cast<double>(n));
    within += std::abs(ratio.back() - 1) < 0.1;
    // Never far below: the finest level alone is accurate to 1 %.
    EXPECT_GT(ratio.back(), 0.95) << "seed " << s;
  }
  EXPECT_NEAR(mean_of(ratio), 1.0, 0.1)
      << "mean sem / (sigma/sqrt(n)) over " << repeats << " series; " << within << " of "
      << repeats << " single series within 10 %";
  // every sample independent
  EXPECT_NEAR(mean_of(independent), 1.0, 0.1) << "mean independent_samples / n";
  RecordProperty("mean_independent_ratio", std::to_string(mean_of(independent)));
}

TEST(BlockAverage, Ar1SemMatchesTheAsymptoticFormula) {
  constexpr std::size_t n = 1 << 16;
  constexpr double rho = 0.9, sigma_x = 1.5;
  constexpr int repeats = 32;
  // Var(mean) = sigma_x^2 (1+rho)/(1-rho)/n up to O(1/n^2) (relative 3e-3 here).
  const double exact = sigma_x * std::sqrt((1 + rho) / (1 - rho) / static_cast<double>(n));
  std::vector<double> ratio, independent;
  for (int s = 0; s < repeats; ++s) {
    const BlockAverage b = block_average(ar1(n, rho, sigma_x, 2000 + s));
    ratio.push_back(b.sem / exact);
    // n (1 - rho) / (1 + rho) = n / 19 independent samples
    independent.push_back(b.independent_samples * (1 + rho) / ((1 - rho) * static_cast<double>(n)));
    EXPECT_GT(ratio.back(), 0.75) << "seed " << s;
    EXPECT_LT(ratio.back(), 2.0) << "seed " << s;
  }
  EXPECT_NEAR(mean_of(ratio), 1.0, 0.2) << "mean sem / exact over " << repeats << " series";
  EXPECT_NEAR(mean_of(independent), 1.0, 0.2) << "mean independent_samples / (n (1 - rho) / (1 + rho))";
  RecordProperty("mean_independent_ratio", std::to_string(mean_of(independent)));
  RecordProperty("mean_ratio", std::to_string(mean_of(ratio)));
  // The naive (uncorrelated) estimate would be too small by sqrt(19).
  const BlockAverage one = block_average(ar1(n, rho, sigma_x, 7));
  EXPECT_GT(one.sem, 3 * sigma_x / std::sqrt(static_cast<double>(n)));
}

TEST(BlockAverage, ConstantSeriesHasExactMeanAndZeroSem) {
  for (const double c : {2.5, -0.125, 0.1, 4928.97, 2792.5268031909272, -1e-3})
    for (const std::size_t n : {std::size_t{1000}, std::size_t{4096}, std::size_t{12345}}) {
      const BlockAverage b = block_average(std::vector<double>(n, c));
      char where[64];
      std::snprintf(where, sizeof where, "c = %.17g, n = %zu", c, n);
      EXPECT_TRUE(b.mean == c && b.sem == 0.0)
          << where << ": mean - c = " << b.mean - c << ", sem = " << b.sem;
      EXPECT_EQ(b.half_difference, 0.0) << where;
      EXPECT_EQ(b.drift_z, 0.0) << where;
      EXPECT_EQ(b.independent_samples, 0.0) << where;
    }
}

TEST(BlockAverage, LinearTrendIsFlaggedAsDrift) {
  constexpr std::size_t n = 10000;
  constexpr double sigma = 1.0, rise = 3.0;  // total rise over the series, in sigma
  for (int s = 0; s < 20; ++s) {
    std::vector<double> up = white_noise(n, 0, sigma, 3000 + s), down = up;
    for (std::size_t i = 0; i < n; ++i) {
      const double trend = rise * static_cast<double>(i) / static_cast<double>(n);
      up[i] += trend;
      down[i] -= trend;
    }
    const BlockAverage u = block_average(up), d = block_average(down);
    EXPECT_GT(u.drift_z, 5) << "seed " << s;
    EXPECT_LT(d.drift_z, -5) << "seed " << s;
    if (s == 0) RecordProperty("drift_z_seed_0", std::to_string(u.drift_z));
    EXPECT_NEAR(u.half_difference, rise / 2, 0.1) << "seed " << s;
  }
}

TEST(BlockAverage, PureNoiseRarelyFlagsDrift) {
  constexpr int seeds = 50;
  int quiet_white = 0, quiet_ar1 = 0;
  for (int s = 0; s < seeds; ++s) {
    quiet_white += std::abs(block_average(white_noise(4096, 1.0, 1.0, 4000 + s)).drift_z) < 3;
    quiet_ar1 += std::abs(block_average(ar1(1 << 14, 0.9, 1.0, 5000 + s)).drift_z) < 3;
  }
  EXPECT_GE(quiet_white, 48) << "of " << seeds << " white-noise series, |drift_z| < 3";
  EXPECT_GE(quiet_ar1, 48) << "of " << seeds << " AR(1) series, |drift_z| < 3";
}


// Few correlation times per window, as in the long-memory runs of the
// coupled models (reports/study/paper): a stationary AR(1) series of 4096
// samples with a correlation time of 64, 128 or 256 samples (32, 16 and 8
// per half). The drift test must keep near its nominal rate of false alarms
// and the standard error must cover the mean at about its nominal rate.
// Before the block correlation was corrected for (block_average.cpp) these
// rates were, measured here: drift flags 8 / 14 / 18 %, mean outside two
// standard errors 17 / 25 / 34 %; after it 1 / 2.7 / 5 % and 4.7 / 3.7 /
// 7.3 % (nominal 0.27 % and 4.6 %).
TEST(BlockAverage, FewCorrelationTimesKeepTheTestsCalibrated) {
  constexpr std::size_t n = 4096;
  constexpr int series = 300;
  int outside_total = 0;
  for (const double tau : {64.0, 128.0, 256.0}) {
    int flagged = 0, outside = 0;
    for (int s = 0; s < series; ++s) {
      const BlockAverage b =
          block_average(ar1(n, std::exp(-1.0 / tau), 1.0, 9000 + static_cast<std::uint64_t>(s) + 1000 * static_cast<std::uint64_t>(tau)));
      flagged += std::abs(b.drift_z) > 3;
      outside += std::abs(b.mean) > 2 * b.sem;
    }
    outside_total += outside;
    RecordProperty("drift_flags_tau_" + std::to_string(static_cast<int>(tau)), flagged);
    RecordProperty("outside_2se_tau_" + std::to_string(static_cast<int>(tau)), outside);
    std::printf("tau %g samples: %d of %d flagged as drifting, %d with the mean outside 2 SE\n", tau, flagged,
                series, outside);
    // Nominal 0.27 %; 3 % allows the binomial scatter of 300 series. With 8
    // correlation times per half a slow fluctuation and a drift are hard to
    // tell apart (the drift test's error comes from the detrended halves):
    // up to 7 % there.
    const int allowed = tau < 200 ? 9 : 21;
    EXPECT_LE(flagged, allowed) << "tau = " << tau << " samples: stationary series flagged as drifting, of "
                                << series;
    EXPECT_LE(outside, 36) << "tau = " << tau << " samples: mean outside two standard errors, of " << series;
  }
  // Pooled: near the nominal 4.6 %, neither too small nor too large an error bar.
  EXPECT_GE(outside_total, 9) << "of " << 3 * series << ": the error bar is far too wide";
  EXPECT_LE(outside_total, 72) << "of " << 3 * series << ": the error bar is too narrow";
}

}  // namespace
}  // namespace mrf
