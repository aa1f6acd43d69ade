// Settling sphere (REFERENCE.md TEST 3.1): constant force plus Stokes drag.
// The exponential velocity Verlet is exact at any step; the overdamped
// integrator is off by exactly the inertial lag, O(St).
#include <gtest/gtest.h>

#include "mrf/forces/drag.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/integrate/steps.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, rho = 7800, eta = 0.1;
const double mass = rho * sphere_volume(R);
const double gamma_ = stokes_gamma(eta, R);
const double tau = mass / gamma_;
const Vec3 F(0, 0, -3e-6);  // N, any constant force
const Vec3 vt = F / gamma_;

Vec3 v_exact(double t) { return vt * (-std::expm1(-t / tau)); }
Vec3 x_exact(double t) { return vt * (t + tau * std::expm1(-t / tau)); }

TEST(Settling, RelaxationTimeOfIron) { EXPECT_NEAR(tau, 1.083e-7, 0.001e-7); }

TEST(Settling, ExponentialVerletIsExactAtAnyStep) {
  for (double dt_over_tau : {0.01, 0.3, 1.0, 7.0, 300.0}) {
    const double dt = dt_over_tau * tau;
    std::vector<Vec3> x{Vec3::Zero()}, v{Vec3::Zero()}, f{F}, w;
    for (int n = 1; n <= 50; ++n) {
      exp_verlet_advance(x, v, f, w, tau, gamma_, 0.0, dt);
      exp_verlet_correct(x, v, f, w, tau, gamma_, 0.0, dt);
      const double t = n * dt;
      ASSERT_LT((v[0] - v_exact(t)).norm(), 1e-10 * vt.norm()) << "dt/tau " << dt_over_tau;
      ASSERT_LT((x[0] - x_exact(t)).norm(), 1e-10 * x_exact(t).norm()) << "dt/tau " << dt_over_tau;
    }
  }
}

TEST(Settling, ExponentialVerletFollowsShearProfile) {
  // Force-free particle released at rest at x = x0 in u = gdot x: relaxes to u.
  const double gdot = 1e4, x0 = 2e-5;
  std::vector<Vec3> x{Vec3(x0, 0, 0)}, v{Vec3::Zero()}, f{Vec3::Zero()}, w;
  const double dt = 0.5 * tau;
  for (int n = 1; n <= 40; ++n) {
    exp_verlet_advance(x, v, f, w, tau, gamma_, gdot, dt);
    exp_verlet_correct(x, v, f, w, tau, gamma_, gdot, dt);
    const double t = n * dt;
    EXPECT_NEAR(v[0].z(), gdot * x0 * (-std::expm1(-t / tau)), 1e-12 * gdot * x0);
    EXPECT_NEAR(x[0].z(), gdot * x0 * (t + tau * std::expm1(-t / tau)), 1e-12 * gdot * x0 * t);
  }
}

TEST(Settling, OverdampedHasTerminalVelocityFromFirstStepAndInertialLag) {
  // v = v_t exactly; x(t) = v_t t, whose error against the inertial solution
  // is the lag v_t tau (1 - e^{-t/tau}) -> v_t tau, i.e. relative St-like error.
  const double dt = 50 * tau;
  std::vector<Vec3> x{Vec3::Zero()}, v{Vec3::Zero()}, f{F};
  for (int n = 1; n <= 20; ++n) {
    overdamped_drift(x, v, f, gamma_, 0.0, dt);
    const double t = n * dt;
    EXPECT_LT((v[0] - vt).norm(), 1e-14 * vt.norm());
    const Vec3 err = x[0] - x_exact(t);
    EXPECT_NEAR(err.z(), vt.z() * tau * (-std::expm1(-t / tau)), 1e-9 * std::abs(vt.z()) * tau);
  }
}

TEST(Settling, ExponentialVerletLimitIsVelocityVerletWithoutDrag) {
  // tau -> infinity: the oscillator limit approaches 2/omega.
  const double omega = 1e8;
  EXPECT_NEAR(verlet_exp_oscillator_limit(omega, 1e6 / omega) * omega, 2.0, 1e-3);
  // tau -> 0 (overdamped): the limit approaches explicit Euler's 2/(omega^2 tau).
  const double t_small = 1e-4 / omega;
  EXPECT_NEAR(verlet_exp_oscillator_limit(omega, t_small) * omega * omega * t_small, 2.0, 2e-2);
}

}  // namespace
}  // namespace mrf
