// Convergence of the explicit SPH solver with resolution on start-up Couette
// (t = 0.05 L^2/nu, the profile still curved) and Poiseuille (t = 0.2 L^2/nu).
// Expected order 2: the Wendland sums with the lattice corrections are exact
// to second moments (interior truncation O(h^2)); the linear wall
// extrapolation has an O(1) truncation error in one layer of width O(dx),
// whose effect on the profile is O(dx^2) because the Green's function
// vanishes at the wall; and explicit Euler at dt ~ h^2/nu adds O(h^2).
// h/dx = 1.3 fixed. Fast: 10, 15, 20 across (pre-asymptotic, wider band);
// Slow: 15, 30, 60.
#include <gtest/gtest.h>

#include <chrono>

#include "support/fit_order.hpp"
#include "sph_channel.hpp"

namespace mrf::test {
namespace {

double couette_error(int n) {
  FluidCell c = channel(n, 100.0, 0.0);
  run_to(c, 0.05 * k_t_visc, explicit_dt(c), false);
  return profile_error(c, couette_exact(c, c.time));
}

double poiseuille_error(int n) {
  FluidCell c = channel(n, 0.0, 8.0 * 7.5e-3 * k_nu / (k_gap * k_gap));
  run_to(c, 0.2 * k_t_visc, explicit_dt(c), false);
  return profile_error(c, poiseuille_exact(c, c.time));
}

void expect_order(const std::vector<int>& ns, double (*error)(int), double band) {
  std::vector<double> h, e;
  const auto t0 = std::chrono::steady_clock::now();
  for (int n : ns) {
    h.push_back(k_gap / n);
    e.push_back(error(n));
    if (e.size() > 1) {
      EXPECT_LT(e.back(), e[e.size() - 2]) << "error must fall with resolution, n = " << n;
    }
    ::testing::Test::RecordProperty("err_n" + std::to_string(n), std::to_string(e.back()));
  }
  const OrderFit fit = fit_order(h, e);
  ::testing::Test::RecordProperty("order", std::to_string(fit.order));
  ::testing::Test::RecordProperty(
      "wall_seconds", std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  EXPECT_NEAR(fit.order, 2.0, band) << "observed order " << fit.order << " +- " << fit.stderr_order;
}

TEST(SphConvergence, CouetteCoarseResolutions) { expect_order({10, 15, 20}, couette_error, 0.3); }

TEST(SphConvergence, PoiseuilleCoarseResolutions) { expect_order({10, 15, 20}, poiseuille_error, 0.3); }

TEST(SphConvergenceSlow, CouetteOrderTwo) { expect_order({15, 30, 60}, couette_error, 0.15); }

TEST(SphConvergenceSlow, PoiseuilleOrderTwo) { expect_order({15, 30, 60}, poiseuille_error, 0.15); }

}  // namespace
}  // namespace mrf::test
