// The start-up series of REFERENCE.md §5 (TESTS 5.2, 5.3) that the SPH tests
// compare against: initial condition, boundary values, steady limits.
#include <gtest/gtest.h>

#include <cmath>

#include "mrf/fluid/analytic.hpp"
#include "mrf/vec.hpp"

namespace mrf {
namespace {

constexpr double k_L = 150e-6, k_nu = 1e-4, k_T = k_L * k_L / k_nu;

TEST(SphAnalytic, CouetteStartsAtRestAndEndsLinear) {
  for (double x : {0.1, 0.3, 0.5, 0.77}) {
    EXPECT_NEAR(couette_startup_velocity(x * k_L, 1e-9 * k_T, k_L, k_nu, -1.0, 1.0), 0.0, 1e-6);
    EXPECT_NEAR(couette_startup_velocity(x * k_L, 10 * k_T, k_L, k_nu, -1.0, 1.0), -1.0 + 2.0 * x, 1e-12);
    EXPECT_NEAR(couette_startup_velocity(x * k_L, 10 * k_T, k_L, k_nu, 0.0, 3.0), 3.0 * x, 1e-12);
  }
  EXPECT_NEAR(couette_startup_velocity(0.0, 0.01 * k_T, k_L, k_nu, -1.0, 1.0), -1.0, 1e-12);
  EXPECT_NEAR(couette_startup_velocity(k_L, 0.01 * k_T, k_L, k_nu, -1.0, 1.0), 1.0, 1e-12);
  // Antisymmetric about the mid-plane for walls at -V, +V.
  EXPECT_NEAR(couette_startup_velocity(0.3 * k_L, 0.02 * k_T, k_L, k_nu, -1.0, 1.0),
              -couette_startup_velocity(0.7 * k_L, 0.02 * k_T, k_L, k_nu, -1.0, 1.0), 1e-12);
}

TEST(SphAnalytic, CouetteWallShearRateFromSemiInfiniteLimit) {
  // Early on each wall sees a semi-infinite fluid: du/dx = V/sqrt(pi nu t),
  // V the wall speed relative to the fluid.
  const double t = 1e-3 * k_T;
  EXPECT_NEAR(couette_startup_shear_rate(0.0, t, k_L, k_nu, -1.0, 1.0), 1.0 / std::sqrt(k_pi * k_nu * t), 1e-6 / std::sqrt(k_nu * t));
  EXPECT_NEAR(couette_startup_shear_rate(0.5 * k_L, 10 * k_T, k_L, k_nu, -1.0, 1.0), 2.0 / k_L, 1e-9 / k_L);
}

TEST(SphAnalytic, PoiseuilleStartsAtRestAndEndsParabolic) {
  const double f = 100.0;
  for (double x : {0.1, 0.5, 0.9}) {
    EXPECT_NEAR(poiseuille_startup_velocity(x * k_L, 1e-9 * k_T, k_L, k_nu, f), 0.0, 1e-9);
    EXPECT_NEAR(poiseuille_startup_velocity(x * k_L, 10 * k_T, k_L, k_nu, f), f * x * (1 - x) * k_L * k_L / (2 * k_nu), 1e-15);
  }
  EXPECT_NEAR(poiseuille_startup_velocity(0.5 * k_L, 10 * k_T, k_L, k_nu, f), f * k_L * k_L / (8 * k_nu), 1e-15);
}

}  // namespace
}  // namespace mrf
