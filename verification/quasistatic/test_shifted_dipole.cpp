// The shifted-force dipole law of the quasi-static driver
// (quasistatic/shifted_dipole.hpp): continuous energy and force at the
// cut-off, F = -grad U by central differences with the error of order 2, and
// the law of forces/dipole.hpp up to the closed-form shift terms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mrf/forces/dipole.hpp"
#include "mrf/quasistatic/aqs.hpp"
#include "mrf/quasistatic/shifted_dipole.hpp"
#include "support/fit_order.hpp"
#include "support/iron_pair.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, M = 1e6, rc = 15e-6;
const double pref = dipole_prefactor(dipole_moment(R, M));

// Unit vectors: along the field, across it, at the magic angle and random.
std::vector<Vec3> directions() {
  std::vector<Vec3> d = {Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), Vec3(1, 0, std::sqrt(2.0)).normalized(),
                         Vec3(-0.3, 0.5, 0.8).normalized()};
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  for (int i = 0; i < 10; ++i) d.push_back(Vec3(g(rng), g(rng), g(rng)).normalized());
  return d;
}

TEST(ShiftedDipole, EnergyAndForceVanishContinuouslyAtCutoff) {
  for (const Vec3& n : directions()) {
    // Zero at r_c up to the round-off of |rc n| (which may fall just inside)
    // and exactly zero beyond, against the jump of the unshifted law there
    // (U ~ pref/(3 r_c^3), F ~ pref / r_c^4).
    const double scale_u = pref / (3 * rc * rc * rc), scale_f = pref / std::pow(rc, 4);
    EXPECT_LT(std::abs(shifted_dipole_energy_x(rc * n, pref, rc)), 1e-14 * scale_u);
    EXPECT_LT(shifted_dipole_force_x(rc * n, pref, rc).norm(), 1e-14 * scale_f);
    EXPECT_EQ(shifted_dipole_energy_x(1.001 * rc * n, pref, rc), 0.0);
    EXPECT_EQ(shifted_dipole_force_x(1.001 * rc * n, pref, rc).norm(), 0.0);
    // approached from inside: U = O(delta^2), F = O(delta)
    for (double delta : {1e-3, 1e-4, 1e-5}) {
      const Vec3 r = (1 - delta) * rc * n;
      EXPECT_LT(std::abs(shifted_dipole_energy_x(r, pref, rc)), 30 * delta * delta * scale_u) << delta;
      EXPECT_LT(shifted_dipole_force_x(r, pref, rc).norm(), 30 * delta * scale_f) << delta;
    }
  }
}

// Central differences at random separations between contact and r_c: the
// error of the difference quotient falls as eps^2.
TEST(ShiftedDipole, ForceIsMinusGradientWithSecondOrderDifferences) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(2 * R, 0.9 * rc);
  const auto energy = [](const Vec3& r) { return shifted_dipole_energy_x(r, pref, rc); };
  for (const Vec3& n : directions()) {
    const Vec3 r = u(rng) * n;
    const Vec3 f = shifted_dipole_force_x(r, pref, rc);
    std::vector<double> eps, err;
    for (double e = 2e-2; e > 1e-3; e /= 2) {
      eps.push_back(e * r.norm());
      err.push_back((f + test::fd_gradient(energy, r, e * r.norm())).norm() / f.norm());
    }
    EXPECT_LT(err.back(), 1e-4);  // at eps = 1.25e-3 r
    for (std::size_t i = 1; i < err.size(); ++i) EXPECT_LT(err[i], err[i - 1]);
    const test::OrderFit fit = test::fit_order(eps, err);
    EXPECT_NEAR(fit.order, 2.0, 0.15) << "r = " << r.transpose();
  }
}

// Well inside r_c: the unshifted law plus the shift terms in closed form,
//   F_sf - F = -pref (1 - 3c^2) r_c^-4 r^ + 2 pref c ((3r - 4 r_c)/r_c^4)(x^ - c r^)/r,
//   U_sf - U = (pref/3)(1 - 3c^2)(-r_c^-3 + 3 (r - r_c) r_c^-4),
// and the difference falls as r_c^-3 at fixed r (the angular term).
TEST(ShiftedDipole, UnshiftedLawUpToShiftTerms) {
  for (const Vec3& n : directions()) {
    for (double r : {2 * R, 3 * R, 5 * R}) {
      const Vec3 rv = r * n;
      const double c = n.x();
      const Vec3 x_hat(1, 0, 0);
      const Vec3 df = -pref * (1 - 3 * c * c) / std::pow(rc, 4) * n +
                      2 * pref * c * (3 * r - 4 * rc) / std::pow(rc, 4) * (x_hat - c * n) / r;
      const Vec3 f = dipole_force_x(rv, pref);
      EXPECT_LT((shifted_dipole_force_x(rv, pref, rc) - f - df).norm(), 1e-12 * f.norm());
      const double du = pref / 3 * (1 - 3 * c * c) * (-1 / std::pow(rc, 3) + 3 * (r - rc) / std::pow(rc, 4));
      const double e = dipole_energy_x(rv, pref);
      EXPECT_NEAR(shifted_dipole_energy_x(rv, pref, rc), e + du, 1e-13 * pref / (3 * r * r * r));  // e = 0 at the magic angle
    }
  }
  // head-to-tail at contact: still the attraction of TEST 1.1, within (2R/r_c)^3
  const Vec3 f = shifted_dipole_force_x(Vec3(2 * R, 0, 0), pref, rc);
  EXPECT_LT(f.x(), 0.0);
  EXPECT_NEAR(f.x(), -dipole_contact_force(R, M), 4 * std::pow(2 * R / rc, 3) * dipole_contact_force(R, M));
  // the difference at fixed r falls as r_c^-3 (the angular shift term)
  const Vec3 rv = 3 * R * Vec3(1, 0.4, 0.7).normalized();
  std::vector<double> cut, diff;
  for (double k : {8.0, 16.0, 32.0, 64.0}) {
    cut.push_back(k * R);
    diff.push_back((shifted_dipole_force_x(rv, pref, k * R) - dipole_force_x(rv, pref)).norm());
  }
  EXPECT_NEAR(test::fit_order(cut, diff).order, -3.0, 0.15);
}

// The scene's pair loop (scene/dem_forces.hpp) running this evaluator gives
// the pure function's force, +-F, and energy.
TEST(ShiftedDipole, PairLoopRunsTheLaw) {
  const DemParams p = dem_params(test::iron_pair_config(R, M, rc));
  ShearCell cell;
  cell.box = Box{100e-6, 40e-6, 40e-6};
  const Vec3 r_ik(4e-6, 1e-6, -7e-6);
  cell.free.x = {Vec3(0, 20e-6, 1e-6) + r_ik, Vec3(0, 20e-6, 1e-6)};  // r_ik crosses z = 0: minimum image
  QuasistaticState s = make_quasistatic_state(cell, p, rc);
  evaluate_forces(s);
  const Vec3 f = shifted_dipole_force_x(r_ik, pref, rc);
  EXPECT_LT((s.cell.free.f[0] - f).norm(), 1e-13 * f.norm());
  EXPECT_LT((s.cell.free.f[1] + f).norm(), 1e-13 * f.norm());
  EXPECT_NEAR(s.sums.energy_dipole, shifted_dipole_energy_x(r_ik, pref, rc),
              1e-13 * std::abs(s.sums.energy_dipole));
  EXPECT_EQ(s.sums.energy_hertz, 0.0);
}

}  // namespace
}  // namespace mrf
