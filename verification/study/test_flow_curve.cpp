// Flow-curve fits (REFERENCE §7) on synthetic data with known parameters.
#include "mrf/study/flow_curve.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mrf/vec.hpp"

namespace mrf {
namespace {

struct Synthetic {
  std::vector<double> mn, eta_r, err;
};

Synthetic make(double eta_inf, double mn_star, double delta, double rel_noise, unsigned seed) {
  Synthetic s;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  for (double lm = -4; lm <= 0.01; lm += 0.5) {
    const double mn = std::pow(10.0, lm);
    const double exact = eta_inf * (1 + std::pow(mn_star / mn, delta));
    const double sigma = std::max(rel_noise, 1e-9) * exact;
    s.mn.push_back(mn);
    s.eta_r.push_back(exact + (rel_noise > 0 ? sigma * g(rng) : 0.0));
    s.err.push_back(sigma);
  }
  return s;
}

TEST(FlowCurve, PowerLawRecoversExactParameters) {
  const Synthetic s = make(2.7, 0.05, 0.8, 0.0, 1);
  const FlowFit f = fit_power_law(s.mn, s.eta_r, s.err);
  ASSERT_TRUE(f.ok) << f.message;
  EXPECT_NEAR(f.eta_inf, 2.7, 1e-6);
  EXPECT_NEAR(f.mason_star, 0.05, 1e-7);
  EXPECT_NEAR(f.exponent, 0.8, 1e-7);
  EXPECT_NEAR(flow_curve_eta_r(f, 1e-3), 2.7 * (1 + std::pow(50.0, 0.8)), 1e-5);
}

// With 3 % noise the estimates scatter by about their error bars: over 40
// synthetic data sets the pulls (estimate - truth)/err have mean ~0 and
// standard deviation ~1. A wrong covariance or a biased fit fails this.
TEST(FlowCurve, PowerLawErrorBarsAreCalibrated) {
  double sum = 0, sum2 = 0;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    const Synthetic s = make(2.7, 0.05, 0.8, 0.03, 100 + static_cast<unsigned>(k));
    const FlowFit f = fit_power_law(s.mn, s.eta_r, s.err);
    ASSERT_TRUE(f.ok) << f.message;
    const double pull = (f.exponent - 0.8) / f.exponent_err;
    sum += pull;
    sum2 += pull * pull;
    EXPECT_LT(f.exponent_err, 0.05);
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_LT(std::abs(mean), 0.5);
  EXPECT_GT(sd, 0.6);
  EXPECT_LT(sd, 1.5);
}

TEST(FlowCurve, BinghamIsExactOnBinghamDataAndRejectsOtherExponents) {
  const Synthetic s = make(1.9, 0.02, 1.0, 0.0, 1);
  const FlowFit b = fit_bingham(s.mn, s.eta_r, s.err);
  ASSERT_TRUE(b.ok) << b.message;
  EXPECT_NEAR(b.eta_inf, 1.9, 1e-6);
  EXPECT_NEAR(b.mason_star, 0.02, 1e-8);
  const Synthetic casson = make(1.9, 0.02, 0.7, 0.01, 5);
  const FlowFit bc = fit_bingham(casson.mn, casson.eta_r, casson.err);
  EXPECT_GT(bc.chi2_dof, 100.0);  // the Bingham form cannot describe Delta = 0.7
  const FlowFit pc = fit_power_law(casson.mn, casson.eta_r, casson.err);
  EXPECT_LT(pc.chi2_dof, 3.0);
  EXPECT_NEAR(pc.exponent, 0.7, 4 * pc.exponent_err);
}

TEST(FlowCurve, RelativeViscosityOfTheCarrierIsOne) {
  const double eta = 0.1, m = 1e6, mn = 1e-2;
  const double gdot = 2 * k_mu0 * m * m * mn / (9 * eta);
  EXPECT_NEAR(relative_viscosity(eta * gdot, mn, eta, m), 1.0, 1e-14);
  EXPECT_NEAR(relative_viscosity(3 * eta * gdot, mn, eta, m), 3.0, 1e-14);
}

TEST(FlowCurve, SeedAverageCombinesScatterAndWithinRunErrors) {
  const std::vector<StressSample> s{{0.1, 1, 100, 1, 10}, {0.1, 2, 110, 1, 10}, {0.01, 1, 50, 5, 1}};
  const auto pts = seed_average(s);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[0].mason, 0.01);
  EXPECT_EQ(pts[0].seeds, 1);
  EXPECT_DOUBLE_EQ(pts[0].err, 5.0);
  EXPECT_DOUBLE_EQ(pts[1].stress, 105.0);
  EXPECT_NEAR(pts[1].seed_scatter, std::sqrt(50.0), 1e-12);
  EXPECT_NEAR(pts[1].within_err, std::sqrt(2.0) / 2, 1e-12);
  EXPECT_NEAR(pts[1].err, 5.0, 1e-12);  // scatter/sqrt(2) dominates
}

}  // namespace
}  // namespace mrf
