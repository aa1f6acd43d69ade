// Implicit (backward Euler) Morris viscosity: agreement with the explicit
// solver on start-up Couette, stability and bounded error far beyond the
// explicit viscous limit, and at Re <= 1e-4 with real and high viscosity.
#include <gtest/gtest.h>

#include <chrono>

#include "mrf/error.hpp"
#include "sph_channel.hpp"

namespace mrf::test {
namespace {

constexpr double k_gdot = 100.0;

TEST(SphImplicit, AgreesWithExplicitOnStartupCouette) {
  // Same dt (half the explicit viscous limit); both are first order in time.
  FluidCell e = channel(15, k_gdot, 0.0), i = channel(15, k_gdot, 0.0);
  const double dt = explicit_dt(e);
  for (double t : {0.05, 0.3}) {
    run_to(e, t * k_t_visc, dt, false);
    run_to(i, t * k_t_visc, dt, true);
    EXPECT_LT(velocity_difference(i, e), t < 0.1 ? 1e-2 : 1e-4) << "t/T = " << t;
  }
  EXPECT_NEAR(wall_shear_stress(i).tau, k_eta * k_gdot, 1e-3 * k_eta * k_gdot);
}

TEST(SphImplicit, StableAndBoundedFarBeyondViscousLimit) {
  // 10x and 30x the explicit viscous limit, within the CFL limit that stays
  // binding for the pressure (gdot = 10/s: c0 = 0.32 m/s, CFL = 48x the
  // viscous limit): no NaN, start-up error bounded, steady state exact.
  // Measured errors at t = 0.05 T: 4e-2 (10x), 8e-2 (30x).
  for (double factor : {10.0, 30.0}) {
    FluidCell c = channel(15, 10.0, 0.0);
    const double dt = factor * viscous_limit(c);
    ASSERT_LT(dt, binding(stability_limits(c, SphImplicit::viscosity)).dt);
    ASSERT_NO_THROW(check_time_step(c, dt, SphImplicit::viscosity));
    EXPECT_THROW(check_time_step(c, dt, SphImplicit::none), InputError);
    const auto t0 = std::chrono::steady_clock::now();
    run_to(c, 0.05 * k_t_visc, dt, true);
    EXPECT_LT(profile_error(c, couette_exact(c, c.time)), 0.12) << factor << "x";
    run_to(c, 0.5 * k_t_visc, dt, true);
    EXPECT_LT(profile_error(c, couette_exact(c, c.time)), 1e-4) << factor << "x";
    EXPECT_NEAR(wall_shear_stress(c).tau, k_eta * 10.0, 1e-3 * k_eta * 10.0);
    RecordProperty("seconds_" + std::to_string(int(factor)) + "x",
                   std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  }
}

TEST(SphImplicit, ExplicitBeyondViscousLimitBlowsUpAndIsDetected) {
  // The same 10x step explicitly must fail loudly, not silently.
  FluidCell c = channel(15, k_gdot, 0.0);
  EXPECT_THROW(run_to(c, 0.3 * k_t_visc, 10 * viscous_limit(c), false), NumericalError);
}

TEST(SphImplicit, LowReynoldsHighViscosityStable) {
  // Re = rho gdot L^2/eta = 9e-5 for the oil (eta = 0.1 Pa s) at
  // gdot = 0.4/s and for eta = 10 Pa s at 40/s. Explicit at its automatic
  // dt and implicit at 100x the viscous limit reach the steady profile.
  const struct {
    double eta, gdot;
  } cases[] = {{0.1, 0.4}, {10.0, 40.0}};
  for (const auto [eta, gdot] : cases) {
    FluidCell e = channel(15, gdot, 0.0, eta), i = channel(15, gdot, 0.0, eta);
    ASSERT_LE(reynolds_number(e.params, e.box), 1e-4);
    const double T = k_gap * k_gap * k_rho / eta;
    run_to(e, 0.6 * T, explicit_dt(e), false);
    const double dt_i = std::min(100 * viscous_limit(i), binding(stability_limits(i, SphImplicit::viscosity)).dt);
    run_to(i, 0.6 * T, dt_i, true);
    for (const FluidCell* c : {&e, &i}) {
      EXPECT_LT(profile_error(*c, couette_exact(*c, c->time)), 2e-3) << "eta = " << eta;
      EXPECT_LT(density_stats(*c).max_abs_error, 0.01);
    }
  }
}

}  // namespace
}  // namespace mrf::test
