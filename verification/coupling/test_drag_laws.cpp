// Drag laws of the coupled models, REFERENCE.md §3 (Stokes) and §4
// (Dallavalle / Di Felice, canonical CFDEM variant, model A): Stokes limit,
// TEST 4.1 table, low-Re ratio to Stokes against its closed form, values at
// (Re, eps) points recomputed independently, continuity in Re, direction.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "mrf/coupling/drag_laws.hpp"

namespace mrf {
namespace {

// MRF-like: iron particle in a viscous carrier (§3).
constexpr double kD = 5e-6, kEta = 0.1, kRho = 1000.0;
// Water-like, to reach Re_p up to 1e4 at moderate speeds.
constexpr double kDw = 1e-3, kEtaw = 1e-3, kRhow = 1000.0;

// Slip speed giving a prescribed Re_p = eps d s rho / eta.
double slip_for(double re, double eps, double d, double rho, double eta) { return re * eta / (eps * d * rho); }

const Vec3 kDir = Vec3(0.36, -0.48, 0.8);  // unit vector, not along an axis

// ------------------------------------------------------------------- Stokes

TEST(DragLaws, StokesCoupledIsSixPiEtaR) {
  const double R = 2.5e-6;
  const Vec3 w(1e-3, -2e-3, 5e-4);
  // gamma = 6 pi 0.1 2.5e-6 = 4.71238898e-6 kg/s
  EXPECT_NEAR(stokes_coupled_drag_coefficient(R, kEta), 4.71238898038e-6, 1e-16);
  const Vec3 f = stokes_coupled_drag(w, R, kEta);
  EXPECT_NEAR((f - 4.71238898038e-6 * w).norm(), 0.0, 1e-12 * f.norm());
  // same as the one-way law of model 1 with u - v = w, and as the struct API
  EXPECT_NEAR((f - stokes_drag(Vec3::Zero(), w, stokes_gamma(kEta, R))).norm(), 0.0, 1e-15 * f.norm());
  const StokesCoupledDrag law{R, kEta};
  EXPECT_EQ(drag_force(law, w, 0.3), f);                    // porosity ignored
  EXPECT_EQ(drag_coefficient(law, 1e3, 0.3), stokes_coupled_drag_coefficient(R, kEta));
  EXPECT_GT(f.dot(w), 0.0);  // pulls the particle toward the fluid velocity
}

TEST(DragLaws, ParticleReynoldsContainsPorosity) {
  // 0.5 * 2e-6 * 0.01 * 1000 / 1e-3 = 0.01 (superficial slip, canonical form)
  EXPECT_NEAR(particle_reynolds(0.5, 2e-6, 0.01, 1000.0, 1e-3), 0.01, 1e-15);
  EXPECT_NEAR(particle_reynolds(0.5, 2e-6, -0.01, 1000.0, 1e-3), 0.01, 1e-15);
  EXPECT_EQ(particle_reynolds(0.7, kD, 0.0, kRho, kEta), 0.0);
}

// ---------------------------------------------------------------- TEST 4.1

TEST(DragLaws, Test41DallavalleAndChiTable) {
  struct Row { double re, cd, chi, cd_tol, chi_tol; };
  // tolerances: half a unit of the last printed digit
  for (const Row& r : {Row{1e-3, 23231.65, 3.699974, 5e-3, 5e-7}, Row{1.0, 29.4849, 3.488976, 5e-5, 5e-7},
                       Row{100.0, 1.2321, 3.126377, 5e-5, 5e-7}}) {
    EXPECT_NEAR(dallavalle_cd(r.re), r.cd, r.cd_tol) << "Re = " << r.re;
    EXPECT_NEAR(di_felice_chi(r.re), r.chi, r.chi_tol) << "Re = " << r.re;
  }
}

TEST(DragLaws, ChiMinimumAndLimits) {
  const double re_min = std::pow(10.0, 1.5);
  EXPECT_NEAR(di_felice_chi(re_min), 3.05, 1e-14);
  for (double f : {0.999, 1.001, 0.5, 2.0}) EXPECT_GT(di_felice_chi(f * re_min), 3.05) << f;
  EXPECT_LT(di_felice_chi(0.5 * re_min), di_felice_chi(0.1 * re_min));  // decreasing below the minimum
  EXPECT_LT(di_felice_chi(2.0 * re_min), di_felice_chi(10.0 * re_min)); // increasing above it
  EXPECT_EQ(di_felice_chi(0.0), 3.7);
  EXPECT_NEAR(di_felice_chi(1e-8), 3.7, 1e-12);
  EXPECT_NEAR(di_felice_chi(1e12), 3.7, 1e-12);
  EXPECT_NEAR(di_felice_chi(1e8), 3.7, 1e-9);  // Gaussian tail 0.65 exp(-21.1) = 4.3e-10
  EXPECT_GT(di_felice_chi(1e-3), 3.6999);
}

// ---------------------------------------------------------- low-Re limit

// F_DF / F_Stokes with F_Stokes = 3 pi eta d (u - v); closed form 0.96 eps^-2.7.
double ratio_to_stokes(double re, double eps) {
  const double s = slip_for(re, eps, kD, kRho, kEta);
  const Vec3 w = s * kDir;
  const Vec3 f = di_felice_drag(w, eps, kD, kRho, kEta);
  return f.dot(kDir) / (3.0 * k_pi * kEta * kD * s);
}

TEST(DragLaws, LowReRatioToStokesMatchesClosedForm) {
  EXPECT_NEAR(0.96 * std::pow(0.7, -2.7), 2.515, 5e-4);  // REFERENCE §4 number
  for (double eps : {0.7, 1.0, 0.45}) {
    const double closed = 0.96 * std::pow(eps, -2.7);
    // exact limit u = v: beta_0 / (3 pi eta d)
    EXPECT_NEAR(di_felice_drag_coefficient(0.0, eps, kD, kRho, kEta) / (3.0 * k_pi * kEta * kD), closed,
                1e-13 * closed);
    for (double re : {1e-6, 1e-5, 1e-4, 1e-3}) {
      const double rel = ratio_to_stokes(re, eps) / closed - 1.0;
      // leading correction of C_D Re / 23.04 = (1 + 0.13125 sqrt(Re))^2: ~0.2625 sqrt(Re), positive
      EXPECT_GT(rel, 0.0) << "eps " << eps << " Re " << re;
      EXPECT_LT(rel, 0.27 * std::sqrt(re)) << "eps " << eps << " Re " << re;
      EXPECT_GT(rel, 0.25 * std::sqrt(re)) << "eps " << eps << " Re " << re;
    }
  }
  EXPECT_NEAR(ratio_to_stokes(1e-6, 0.7), 2.515, 2e-3);
  EXPECT_NEAR(ratio_to_stokes(1e-6, 1.0), 0.96, 5e-4);
}

// -------------------------------------------------- independent values

// Same law, arranged differently: C_D expanded, chi through ln, force as
// C_D * dynamic pressure of the superficial slip * frontal area * eps^-chi.
Vec3 di_felice_independent(const Vec3& w, double eps, double d, double rho, double eta) {
  const double s = std::sqrt(w.x() * w.x() + w.y() * w.y() + w.z() * w.z());
  const double re = eps * s * d * rho / eta;
  const double cd = 0.3969 + 6.048 / std::sqrt(re) + 23.04 / re;
  const double lg = std::log(re) / std::log(10.0);
  const double chi = 3.7 - 0.65 / std::exp((lg - 1.5) * (lg - 1.5) / 2.0);
  const double area = k_pi * d * d / 4.0;
  const double q = 0.5 * rho * (eps * s) * (eps * s);
  const double mag = cd * q * area / std::pow(eps, chi);
  return (mag / s) * w;
}

TEST(DragLaws, DiFeliceMatchesIndependentFormula) {
  struct Pt { double re, eps; };
  for (const Pt& p : {Pt{1e-2, 0.4}, Pt{0.5, 0.6}, Pt{3.0, 0.9}, Pt{31.6, 0.5}, Pt{200.0, 0.8}, Pt{1e4, 0.95},
                      Pt{2e-3, 0.7}, Pt{1e-4, 0.6}, Pt{1e-5, 0.5}}) {
    const double s = slip_for(p.re, p.eps, kDw, kRhow, kEtaw);
    const Vec3 w = s * kDir;
    const Vec3 f = di_felice_drag(w, p.eps, kDw, kRhow, kEtaw);
    const Vec3 g = di_felice_independent(w, p.eps, kDw, kRhow, kEtaw);
    EXPECT_NEAR((f - g).norm(), 0.0, 1e-12 * g.norm()) << "Re " << p.re << " eps " << p.eps;
    // and through the C_D / chi functions of the header (model A, eps^(2-chi))
    const double mag = 0.125 * dallavalle_cd(p.re) * kRhow * k_pi * kDw * kDw * std::pow(p.eps, 2.0 - di_felice_chi(p.re)) * s * s;
    EXPECT_NEAR(f.norm(), mag, 1e-12 * mag);
    const DiFeliceDrag law{kDw, kRhow, kEtaw};
    EXPECT_EQ(drag_force(law, w, p.eps), f);
    EXPECT_NEAR((drag_coefficient(law, s, p.eps) * w - f).norm(), 0.0, 1e-15 * f.norm());
  }
}

// ---------------------------------------------------------- continuity

TEST(DragLaws, DiFeliceContinuousInRe) {
  for (double eps : {0.45, 0.7, 1.0}) {
    double prev = 0.0;
    for (int k = 0; k <= 240; ++k) {
      const double re = std::pow(10.0, -8.0 + 12.0 * k / 240.0);
      const double s = slip_for(re, eps, kDw, kRhow, kEtaw);
      const double s2 = slip_for(re * (1.0 + 1e-9), eps, kDw, kRhow, kEtaw);
      const double f1 = di_felice_drag(s * kDir, eps, kDw, kRhow, kEtaw).norm();
      const double f2 = di_felice_drag(s2 * kDir, eps, kDw, kRhow, kEtaw).norm();
      ASSERT_TRUE(std::isfinite(f1));
      // F ~ Re at low Re, ~ Re^2 at high Re: relative step 1e-9 .. 2e-9
      EXPECT_GT(f2, f1) << "Re " << re;
      EXPECT_LT(f2 / f1 - 1.0, 3e-9) << "Re " << re;
      const double b1 = di_felice_drag_coefficient(s, eps, kDw, kRhow, kEtaw);
      const double b2 = di_felice_drag_coefficient(s2, eps, kDw, kRhow, kEtaw);
      EXPECT_LT(std::abs(b2 / b1 - 1.0), 2e-9) << "Re " << re;
      EXPECT_GT(f1, prev);  // monotone in the slip
      prev = f1;
    }
    // smooth approach to the u = v value
    const double b0 = di_felice_drag_coefficient(0.0, eps, kDw, kRhow, kEtaw);
    const double b8 = di_felice_drag_coefficient(slip_for(1e-8, eps, kDw, kRhow, kEtaw), eps, kDw, kRhow, kEtaw);
    EXPECT_GT(b8, b0);
    EXPECT_LT(b8 / b0 - 1.0, 3e-5);
  }
}

// ---------------------------------------------------------- direction

TEST(DragLaws, DiFeliceAlongSlipAntisymmetricZeroAtNoSlip) {
  const Vec3 zero = di_felice_drag(Vec3::Zero(), 0.7, kD, kRho, kEta);
  EXPECT_EQ(zero, Vec3::Zero());
  EXPECT_TRUE(std::isfinite(di_felice_drag_coefficient(0.0, 0.7, kD, kRho, kEta)));
  EXPECT_EQ(drag_force(DiFeliceDrag{kD, kRho, kEta}, Vec3::Zero(), 1.0), Vec3::Zero());
  // no fluid inertia (rho_f = 0): Re = 0, finite Stokes-like limit
  EXPECT_TRUE(di_felice_drag(kDir, 0.7, kD, 0.0, kEta).allFinite());
  EXPECT_TRUE(di_felice_drag(1e-300 * kDir, 0.7, kD, kRho, kEta).allFinite());  // underflows, no NaN
  for (double s : {1e-150, 1e-12, 1e-3, 1.0, 1e3}) {
    const Vec3 w = s * kDir;
    const Vec3 f = di_felice_drag(w, 0.7, kD, kRho, kEta);
    ASSERT_TRUE(f.allFinite()) << s;
    EXPECT_GT(f.dot(w), 0.0) << s;                               // toward the fluid velocity
    EXPECT_LT(f.cross(kDir).norm(), 1e-14 * f.norm()) << s;      // along u - v
    EXPECT_EQ(di_felice_drag(-w, 0.7, kD, kRho, kEta), -f) << s;  // antisymmetric
  }
  // denser bed, more drag at fixed slip
  const Vec3 w = 1e-3 * kDir;
  EXPECT_GT(di_felice_drag(w, 0.5, kD, kRho, kEta).norm(), di_felice_drag(w, 0.7, kD, kRho, kEta).norm());
}

}  // namespace
}  // namespace mrf
