// Fixed point dipoles, REFERENCE.md §1, TEST 1.1: closed forms, Newton's
// third law, F = -grad U by central differences, r^-4 decay.
#include <gtest/gtest.h>

#include <random>

#include "mrf/forces/dipole.hpp"
#include "support/fit_order.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, M = 1e6;
const double m = dipole_moment(R, M);
const Vec3 mx(m, 0, 0);

TEST(Dipole, HeadToTailAttractsWithClosedForm) {
  const double r = 7e-6;
  const Vec3 f = dipole_force(Vec3(r, 0, 0), mx, mx);
  const double expect = -3.0 * k_mu0 * m * m / (2.0 * k_pi * std::pow(r, 4));
  EXPECT_NEAR(f.x(), expect, 1e-13 * std::abs(expect));
  EXPECT_EQ(f.y(), 0.0);
  EXPECT_EQ(f.z(), 0.0);
  EXPECT_LT(f.x(), 0.0);  // i (at +x) pulled toward k
}

TEST(Dipole, SideBySideRepelsHalfAsStrongly) {
  const double r = 6e-6;
  for (const Vec3& n : {Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, -0.6, 0.8)}) {
    const Vec3 f = dipole_force(r * n, mx, mx);
    const double expect = 3.0 * k_mu0 * m * m / (4.0 * k_pi * std::pow(r, 4));
    EXPECT_NEAR((f - expect * n).norm(), 0.0, 1e-13 * expect);
  }
}

TEST(Dipole, ContactNumbersOfReference) {
  // |F| = (pi/6) mu0 R^2 M^2 = 4.1123e-6 N, U = -(pi/9) mu0 R^3 M^2 = -6.854e-12 J
  const Vec3 r(2 * R, 0, 0);
  EXPECT_NEAR(dipole_force(r, mx, mx).norm(), 4.1123e-6, 1e-10);
  EXPECT_NEAR(dipole_contact_force(R, M), 4.1123e-6, 1e-10);
  EXPECT_NEAR(dipole_energy(r, mx, mx), -6.854e-12, 1e-15);
}

TEST(Dipole, SpecialisedEqualMomentsMatchesGeneralForm) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-20e-6, 20e-6);
  const double pref = dipole_prefactor(m);
  for (int t = 0; t < 200; ++t) {
    const Vec3 r(u(rng), u(rng), u(rng));
    if (r.norm() < 2 * R) continue;
    const Vec3 a = dipole_force(r, mx, mx), b = dipole_force_x(r, pref);
    EXPECT_LT((a - b).norm(), 1e-13 * a.norm());
  }
}

// The energy the pair loop sums (DipoleX, scaled once) is the general U.
TEST(Dipole, SpecialisedEqualMomentsEnergyMatchesGeneralForm) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-20e-6, 20e-6);
  const double pref = dipole_prefactor(m);
  for (int t = 0; t < 200; ++t) {
    const Vec3 r(u(rng), u(rng), u(rng));
    if (r.norm() < 2 * R) continue;
    const double a = dipole_energy(r, mx, mx), b = dipole_energy_x(r, pref);
    // relative to the size of the terms, not to U: U passes 0 at the magic angle
    const double terms = 4.0 * k_mu0 * m * m / (4.0 * k_pi * std::pow(r.norm(), 3));
    EXPECT_LT(std::abs(a - b), 1e-13 * terms);
  }
}

TEST(Dipole, NewtonsThirdLawToRoundOff) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int t = 0; t < 100; ++t) {
    const Vec3 r = 1e-5 * Vec3(u(rng), u(rng), u(rng)) + Vec3(6e-6, 0, 0);
    const Vec3 mi = m * Vec3(u(rng), u(rng), u(rng)), mk = m * Vec3(u(rng), u(rng), u(rng));
    const Vec3 fik = dipole_force(r, mi, mk), fki = dipole_force(-r, mk, mi);
    EXPECT_LT((fik + fki).norm(), 1e-15 * fik.norm());
    const double pref = dipole_prefactor(m);
    EXPECT_EQ(dipole_force_x(r, pref), -dipole_force_x(Vec3(-r), pref));
  }
}

TEST(Dipole, ForceIsMinusGradientOfEnergy) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int t = 0; t < 50; ++t) {
    Vec3 r = 1.5e-5 * Vec3(u(rng), u(rng), u(rng));
    if (r.norm() < 2 * R) r *= 2 * R / r.norm() * 1.2;
    const Vec3 mi = m * Vec3(u(rng), u(rng), u(rng)), mk = m * Vec3(u(rng), u(rng), u(rng));
    const Vec3 grad = test::fd_gradient([&](const Vec3& q) { return dipole_energy(q, mi, mk); }, r,
                                        1e-4 * r.norm());
    const Vec3 f = dipole_force(r, mi, mk);
    EXPECT_LT((f + grad).norm(), 1e-6 * f.norm()) << "at r = " << r.transpose();
  }
}

TEST(Dipole, DecaysAsInverseFourthPower) {
  std::vector<double> r, f;
  for (double s = 5e-6; s < 5e-5; s *= 1.5) {
    r.push_back(s);
    f.push_back(dipole_force(Vec3(s, 0, 0), mx, mx).norm());
  }
  EXPECT_NEAR(test::fit_order(r, f).order, -4.0, 1e-10);
}

}  // namespace
}  // namespace mrf
