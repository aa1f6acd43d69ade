// The exact particle + fluid-parcel drag sub-step of the coupled models
// (integrate/coupled_steps.hpp): reduction to model 1's exponential Verlet
// step when the fluid is held (1/M = 0), exactness of the two-body solution,
// the exchanged impulse against its closed form, and stability at steps far
// above the relaxation time.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mrf/integrate/coupled_steps.hpp"
#include "mrf/integrate/steps.hpp"

namespace mrf {
namespace {

constexpr double kMass = 5.1e-13;   // iron sphere R = 2.5 um (kg)
constexpr double kGamma = 4.712e-6; // 6 pi eta R, eta = 0.1 (kg/s)

std::vector<Vec3> random_vectors(std::size_t n, double scale, unsigned seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < n; ++i) out.emplace_back(u(g), u(g), u(g));
  return out;
}

ParcelCoupling held_fluid(std::size_t n) {
  return {std::vector<double>(n, kGamma), std::vector<double>(n, 0.0), std::vector<Vec3>(n, Vec3::Zero())};
}

// With the fluid held at rest (1/M = 0, u = 0) the sub-step is model 1's
// exp_verlet_advance / exp_verlet_correct at zero shear: positions and
// velocities agree to round-off over many steps with changing forces.
TEST(CoupledSteps, HeldFluidReducesToModelOneExponentialVerlet) {
  const std::size_t n = 20;
  const double tau = kMass / kGamma, dt = 2.7e-9;
  auto x1 = random_vectors(n, 1e-5, 1), v1 = random_vectors(n, 0.1, 2);
  auto x2 = x1, v2 = v1;
  const ParcelCoupling c = held_fluid(n);
  ParcelState st{std::vector<Vec3>(n, Vec3::Zero()), std::vector<Vec3>(n, Vec3::Zero())};
  std::vector<Vec3> w;
  auto force = [](const std::vector<Vec3>& x) {  // position-dependent, like contacts
    std::vector<Vec3> f;
    for (const Vec3& p : x) f.emplace_back(-1e-1 * p.x(), 3e-7 * std::sin(1e5 * p.y()), -2e-2 * p.z());
    return f;
  };
  auto f1 = force(x1), f2 = f1;
  for (int k = 0; k < 200; ++k) {
    exp_verlet_advance(x1, v1, f1, w, tau, kGamma, 0.0, dt);
    f1 = force(x1);
    exp_verlet_correct(x1, v1, f1, w, tau, kGamma, 0.0, dt);
    const auto f_old = f2;
    parcel_advance(x2, v2, f_old, c, st, kMass, dt);
    f2 = force(x2);
    parcel_correct(v2, f_old, f2, c, st, kMass, dt);
  }
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR((x1[i] - x2[i]).norm(), 0.0, 1e-14 * x1[i].norm()) << i;
    EXPECT_NEAR((v1[i] - v2[i]).norm(), 0.0, 1e-12 * v1[i].norm() + 1e-18) << i;
  }
}

// Constant forces: the two-body solution is exact, so one step of dt equals
// 1000 steps of dt/1000; mixture momentum changes by exactly (F + M g) dt;
// the impulse equals gamma * integral of the slip from the closed form.
TEST(CoupledSteps, TwoBodyRelaxationIsExactAndImpulseMatchesClosedForm) {
  const double M = 2.0 * kMass, k = 1.0 / M, dt = 5e-7;  // dt ~ 5 tau_p
  const Vec3 F(1e-8, -2e-8, 3e-8), g(0.0, 0.0, 50.0), v0(0.01, 0.0, -0.02), u0(0.0, 0.03, 0.01);
  ParcelCoupling c{{kGamma}, {k}, {g}};
  auto run = [&](int steps) {
    std::vector<Vec3> x{Vec3::Zero()}, v{v0};
    ParcelState st{{u0}, {Vec3::Zero()}};
    for (int s = 0; s < steps; ++s) {
      parcel_advance(x, v, {F}, c, st, kMass, dt / steps);
      parcel_correct(v, {F}, {F}, c, st, kMass, dt / steps);
    }
    return std::tuple{x[0], v[0], st.u[0], st.impulse[0]};
  };
  const auto [x1, v1, u1, j1] = run(1);
  const auto [xk, vk, uk, jk] = run(1000);
  EXPECT_NEAR((x1 - xk).norm(), 0.0, 1e-12 * xk.norm());
  EXPECT_NEAR((v1 - vk).norm(), 0.0, 1e-11 * vk.norm());
  EXPECT_NEAR((j1 - jk).norm(), 0.0, 1e-11 * jk.norm());
  const Vec3 dp = kMass * (v1 - v0) + M * (u1 - u0);
  EXPECT_NEAR((dp - (F + M * g) * dt).norm(), 0.0, 1e-12 * dp.norm());
  // Closed form: s(t) = s_inf + (s0 - s_inf) e^{-lambda t}, J = gamma int s dt.
  const double lambda = kGamma * (1.0 / kMass + k);
  const Vec3 s0 = u0 - v0, s_inf = (g - F / kMass) / lambda;
  const Vec3 j = kGamma * (s_inf * dt + (s0 - s_inf) * (1.0 - std::exp(-lambda * dt)) / lambda);
  EXPECT_NEAR((j1 - j).norm(), 0.0, 1e-12 * j.norm());
}

// dt = 1e4 tau_p: no growth; the slip reaches its steady value g - F/m over
// lambda, i.e. -F/gamma (1 + m/M)^-1 for g = 0: the slip of a particle
// that accelerates its parcel along with it.
TEST(CoupledSteps, StableAndSteadyFarAboveTheRelaxationTime) {
  const double M = 0.3 * kMass, dt = 1e4 * kMass / kGamma;
  const Vec3 F(0.0, 0.0, 4.712e-8);
  ParcelCoupling c{{kGamma}, {1.0 / M}, {Vec3::Zero()}};
  std::vector<Vec3> x{Vec3::Zero()}, v{Vec3(1.0, -2.0, 3.0)};
  ParcelState st{{Vec3::Zero()}, {Vec3::Zero()}};
  for (int s = 0; s < 50; ++s) {
    parcel_advance(x, v, {F}, c, st, kMass, dt);
    parcel_correct(v, {F}, {F}, c, st, kMass, dt);
    ASSERT_TRUE(v[0].allFinite() && st.u[0].allFinite());
  }
  // u and v have grown to ~4e3 m/s (the pair accelerates as a whole), so the
  // slip carries the round-off of those: compare to 1e-15 |v|.
  const Vec3 slip = st.u[0] - v[0];
  const Vec3 expect = -F / (kGamma * (1.0 + kMass / M));  // (g - F/m)/lambda, m lambda = gamma (1 + m/M)
  EXPECT_NEAR((slip - expect).norm(), 0.0, 1e-15 * v[0].norm());
  EXPECT_GT(v[0].z(), 1e3);  // the mixture did accelerate
}

}  // namespace
}  // namespace mrf
