// Unresolved SPH-DEM coupling kernels, REFERENCE.md §6: porosity from kernel
// smoothing, Shepard interpolation at DEM particles, and TEST 6.1 (the
// back-reaction conserves momentum exactly). Fluid from build_fluid_cell
// (simple cubic lattice, h/dx = 1.3, Wendland C2), MRF-scale particles.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/error.hpp"
#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "support/coupling_cell.hpp"

namespace mrf {
namespace {

using namespace mrf::test;  // the fluid cell and particles of support/coupling_cell.hpp

// The Shepard sums, their rate and the buoyancy run on threads by blocks of
// whole DEM runs of the pairs (each DEM particle's sums in one block, in
// the serial order): the same bit for bit on 1, 2 and 3 threads, above the
// block threshold (8192 pairs).
TEST(CouplingExchange, ShepardSumsAreTheSameOnAnyNumberOfThreads) {
  const FluidCell c = make_cell();
  const auto dem = random_points(2500, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 7);
  std::vector<CouplingPair> pairs;
  std::vector<Vec3> dw;
  coupling_pairs(dem, c.fluid.x, c.box, c.h, pairs, &dw);
  ASSERT_GT(pairs.size(), 3u * 8192u);
  const std::size_t na = c.fluid.size();
  std::vector<double> rho(na), eps(na);
  std::vector<Vec3> v(na), acc(na);
  for (std::size_t a = 0; a < na; ++a) {  // smooth, non-uniform fields
    const Vec3& x = c.fluid.x[a];
    rho[a] = 1000.0 * (1.0 + 0.01 * std::sin(x.y() / kDx));
    eps[a] = 0.7 + 0.2 * std::cos(x.z() / kDx);
    v[a] = Vec3(std::sin(x.x() / kDx), 0.1, std::cos(x.y() / kDx));
    acc[a] = Vec3(0.3, std::cos(x.z() / kDx), -0.2);
  }
  const std::vector<Vec3> c_dem(dem.size(), Vec3(0.1, -0.2, 0.3));
  const int saved = omp_get_max_threads();
  auto all = [&](int t) {
    omp_set_num_threads(t);
    const ShepardField sh = shepard_interpolate(dem.size(), pairs, c.mass, rho, v, eps);
    return std::make_tuple(sh, shepard_rate(pairs, dw, c.mass, rho, v, sh, c_dem),
                           generalised_buoyancy(dem.size(), pairs, c.mass, sh.s, acc, kVp));
  };
  const auto one = all(1);
  for (int t : {2, 3}) {
    const auto many = all(t);
    for (std::size_t i = 0; i < dem.size(); ++i) {
      ASSERT_EQ(std::get<0>(many).s[i], std::get<0>(one).s[i]) << t << " threads, DEM " << i;
      ASSERT_EQ(std::get<0>(many).u[i], std::get<0>(one).u[i]) << t << " threads, DEM " << i;
      ASSERT_EQ(std::get<0>(many).eps[i], std::get<0>(one).eps[i]) << t << " threads, DEM " << i;
      ASSERT_EQ(std::get<1>(many)[i], std::get<1>(one)[i]) << t << " threads, DEM " << i;
      ASSERT_EQ(std::get<2>(many)[i], std::get<2>(one)[i]) << t << " threads, DEM " << i;
    }
  }
  omp_set_num_threads(saved);
}

// shepard_rate is the time derivative of the Shepard interpolant at DEM
// particles moving at c_i through SPH particles moving at v_a: central
// differences of shepard_interpolate with every DEM particle at x_i +- e c_i
// and every SPH particle at x_a +- e v_a (the pairs found afresh) agree to
// the differences' truncation error (1e-5: the kernel is only C2 at its
// support), in a normal box and in one narrower than 4h (pairs through two
// images), with random SPH velocities and densities. A sign error, a
// missing -u_i (the Shepard normalisation) or -v_a (the SPH particles'
// motion) fails by O(1).
TEST(CouplingExchange, ShepardRateIsTheTimeDerivativeOfTheInterpolant) {
  for (const Box& box : {Box{24 * kDx, 12 * kDx, 12 * kDx}, Box{24 * kDx, 3 * kDx, 4 * kDx}}) {
    const FluidCell c = make_cell(box);
    const auto dem = random_points(30, -0.4 * box.gap, 0.4 * box.gap, box, 11);
    std::mt19937_64 gen(3);
    std::normal_distribution<double> g;
    std::vector<Vec3> v(c.fluid.size()), dir(dem.size());
    std::vector<double> rho(c.fluid.size()), eps(c.fluid.size(), 1.0);
    for (std::size_t a = 0; a < v.size(); ++a) v[a] = Vec3(g(gen), g(gen), g(gen)), rho[a] = 1000.0 * (1 + 0.1 * g(gen));
    for (auto& d : dir) d = Vec3(g(gen), g(gen), g(gen));
    std::vector<CouplingPair> pairs;
    std::vector<Vec3> dw;
    coupling_pairs(dem, c.fluid.x, box, c.h, pairs, &dw);
    const ShepardField at = shepard_interpolate(dem.size(), pairs, c.mass, rho, v, eps);
    const std::vector<Vec3> rate = shepard_rate(pairs, dw, c.mass, rho, v, at, dir);
    const double e = 2e-4 * kDx / 1.0;  // s: displacements of about 2e-4 dx at 1 m/s
    auto field_at = [&](double sign) {
      std::vector<Vec3> x = dem, xa = c.fluid.x;
      for (std::size_t i = 0; i < x.size(); ++i) x[i] += sign * e * dir[i];
      for (std::size_t a = 0; a < xa.size(); ++a) xa[a] += sign * e * v[a];
      return shepard_interpolate(x.size(), coupling_pairs(x, xa, box, c.h), c.mass, rho, v, eps).u;
    };
    const std::vector<Vec3> up = field_at(1.0), down = field_at(-1.0);
    double largest = 0;
    for (std::size_t i = 0; i < dem.size(); ++i) {
      const Vec3 fd = (up[i] - down[i]) / (2 * e);
      largest = std::max(largest, fd.norm());
      EXPECT_LT((rate[i] - fd).norm(), 1e-5 * fd.norm() + 1e-3) << "particle " << i << ", ly " << box.ly;
    }
    EXPECT_GT(largest, 1e4) << "the field must change (|v| ~ 1 m/s over h ~ 6.5 um at ~1 m/s)";
  }
}

// (1a) Random DEM particles at solid fraction phi = 0.2 filling the slab and
// 2h beyond the fluid in x (so every fluid particle has homogeneous
// surroundings): mean eps over the fluid = 1 - phi within 3 %. The mean is
// nearly deterministic (each particle deposits V_p S1(offset), S1 ~ 1.01).
TEST(CouplingExchange, PorosityMeanIsOneMinusSolidFraction) {
  const FluidCell c = make_cell();
  const double x_lo = -0.5 * c.box.gap - 2.0 * c.h, x_hi = 0.5 * c.box.gap + 2.0 * c.h;
  const double vol = (x_hi - x_lo) * c.box.ly * c.box.lz, phi = 0.2;
  const auto dem = random_points(static_cast<std::size_t>(std::lround(phi * vol / kVp)), x_lo, x_hi, c.box, 7);
  const auto pairs = coupling_pairs(dem, c.fluid.x, c.box, c.h);
  const PorosityField raw = porosity_at_fluid(c.fluid.size(), kVp, pairs, std::numeric_limits<double>::lowest());
  double mean = 0.0;
  std::size_t below = 0;
  for (double e : raw.eps) {
    mean += e;
    below += e < k_porosity_floor ? 1 : 0;
  }
  mean /= static_cast<double>(raw.eps.size());
  EXPECT_EQ(raw.clamped, 0u);
  EXPECT_NEAR(mean, 1.0 - phi, 0.03 * (1.0 - phi));
  const PorosityField clamped = porosity_at_fluid(c.fluid.size(), kVp, pairs);
  EXPECT_EQ(clamped.clamped, below);  // the floor reports every raised value
  for (double e : clamped.eps) EXPECT_GE(e, k_porosity_floor);
}

TEST(CouplingExchange, PorosityFloorClampsDenseCluster) {
  const FluidCell c = make_cell();
  const std::vector<Vec3> dem(200, Vec3(0.0, 0.5 * c.box.ly, 0.5 * c.box.lz));  // 200 V_p at one point
  const PorosityField f = porosity_at_fluid(c.fluid.size(), kVp, coupling_pairs(dem, c.fluid.x, c.box, c.h));
  EXPECT_GT(f.clamped, 0u);
  std::size_t at_floor = 0;
  for (double e : f.eps) at_floor += e == k_porosity_floor ? 1 : 0;
  EXPECT_EQ(at_floor, f.clamped);
}

// (1b) One isolated particle: sum_a (m/rho_a)(1 - eps_a) = V_p S(offset),
// the kernel quadrature S = sum_a dx^3 W(r_ai) (1 in the continuum). At a
// lattice node S is lattice_kernel_sum exactly; elsewhere within 1.5 %.
TEST(CouplingExchange, IsolatedParticleDepositsItsVolume) {
  const FluidCell c = make_cell();
  auto deposited = [&](const Vec3& xi) {
    const auto pairs = coupling_pairs({xi}, c.fluid.x, c.box, c.h);
    const PorosityField f = porosity_at_fluid(c.fluid.size(), kVp, pairs);
    double sum = 0.0;
    for (std::size_t a = 0; a < c.fluid.size(); ++a) sum += c.mass / c.fluid.rho[a] * (1.0 - f.eps[a]);
    return sum;
  };
  const Vec3 node = c.fluid.x[6 * 144 + 5 * 12 + 7];  // interior lattice node
  EXPECT_NEAR(deposited(node), kVp * lattice_kernel_sum(kDx, c.h), 1e-12 * kVp);
  for (const Vec3& xi : random_points(20, -4 * kDx, 4 * kDx, c.box, 3))
    EXPECT_NEAR(deposited(xi), kVp, 0.015 * kVp);
}

// (2) Shepard interpolation of v = (0, 0, g x) and of a constant field.
// Shepard is zeroth-order consistent: a linear field is reproduced exactly
// only where the lattice is mirror-symmetric in x about the particle (x_i at
// a node or mid-node plane, any y, z); elsewhere the error is the first
// kernel moment of the lattice, measured 4.1e-3 g dx at h/dx = 1.3 (seed 12)
// and bounded here by 1e-2 g dx. Particles |x_i| <= gap/2 - 4h see fluid of
// uniform density only.
TEST(CouplingExchange, ShepardReproducesLinearAndConstantFields) {
  FluidCell c = make_cell();
  const double g = 1e3, x_max = 0.5 * c.box.gap - 4.0 * c.h;
  for (std::size_t a = 0; a < c.fluid.size(); ++a) c.fluid.v[a] = Vec3(0.0, 0.0, g * c.fluid.x[a].x());
  const std::vector<double> eps_const(c.fluid.size(), 0.7);
  std::vector<Vec3> sym = random_points(12, 0.0, 1.0, c.box, 11);
  for (std::size_t k = 0; k < sym.size(); ++k) sym[k].x() = (static_cast<double>(k) - 6.0) * 0.5 * kDx;
  const ShepardField fs = shepard_interpolate(sym.size(), coupling_pairs(sym, c.fluid.x, c.box, c.h), c.mass,
                                              c.fluid.rho, c.fluid.v, eps_const);
  for (std::size_t k = 0; k < sym.size(); ++k) {
    EXPECT_NEAR(fs.u[k].z(), g * sym[k].x(), 1e-12 * g * c.box.gap) << "symmetric particle " << k;
    EXPECT_NEAR(fs.u[k].x(), 0.0, 1e-300);
    EXPECT_NEAR(fs.eps[k], 0.7, 1e-14);
  }
  const auto rnd = random_points(40, -x_max, x_max, c.box, 12);
  const ShepardField fr = shepard_interpolate(rnd.size(), coupling_pairs(rnd, c.fluid.x, c.box, c.h), c.mass,
                                              c.fluid.rho, c.fluid.v, eps_const);
  double worst = 0.0;
  for (std::size_t k = 0; k < rnd.size(); ++k) worst = std::max(worst, std::abs(fr.u[k].z() - g * rnd[k].x()));
  EXPECT_LT(worst, 1e-2 * g * kDx);
  RecordProperty("linear_field_max_error_over_g_dx", std::to_string(worst / (g * kDx)));
  // Constant field anywhere, walls included (non-uniform rho there): round-off.
  const Vec3 u0(1e-3, -2e-3, 3e-3);
  std::fill(c.fluid.v.begin(), c.fluid.v.end(), u0);
  const auto any = random_points(40, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 13);
  const ShepardField fc = shepard_interpolate(any.size(), coupling_pairs(any, c.fluid.x, c.box, c.h), c.mass,
                                              c.fluid.rho, c.fluid.v, eps_const);
  for (std::size_t k = 0; k < any.size(); ++k) EXPECT_LT((fc.u[k] - u0).norm(), 1e-14 * u0.norm());
}

// (3) TEST 6.1, discrete identity sum_a m a_a^c + sum_i F_i = 0 with random
// forces, positions (walls included) and a non-uniform density. The
// mutations below must break it; a sign flip in add_back_coupling
// (`-=` -> `+=`) was also tried: residual 7.3e-2 = 2|sum F|/sum|F|, failed.
TEST(CouplingExchange, BackCouplingConservesMomentumExactly) {
  FluidCell c = make_cell();
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> rho = c.fluid.rho;
  for (double& r : rho) r *= 1.0 + 0.01 * u(gen);  // superficial-like density, not uniform
  const auto dem = random_points(300, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 6);
  std::vector<Vec3> F(dem.size());
  Vec3 f_sum = Vec3::Zero();
  double f_abs = 0.0;
  for (Vec3& f : F) {
    f = 1e-9 * Vec3(u(gen), u(gen), u(gen));
    f_sum += f;
    f_abs += f.norm();
  }
  const std::vector<double> eps(c.fluid.size(), 1.0);
  auto residual = [&](const std::vector<CouplingPair>& gather, const std::vector<double>& rho_gather,
                      const std::vector<CouplingPair>& scatter) {
    const ShepardField sh = shepard_interpolate(dem.size(), gather, c.mass, rho_gather, c.fluid.v, eps);
    std::vector<Vec3> a(c.fluid.size(), Vec3(0.0, 0.0, 1.0));  // accumulates onto what is there
    add_back_coupling(scatter, F, sh.s, rho, a);
    Vec3 p = -static_cast<double>(c.fluid.size()) * c.mass * Vec3(0.0, 0.0, 1.0);
    for (const Vec3& aa : a) p += c.mass * aa;
    return (p + f_sum).norm() / f_abs;
  };
  const auto pairs = coupling_pairs(dem, c.fluid.x, c.box, c.h);
  EXPECT_LT(residual(pairs, rho, pairs), 1e-12);
  // Mutations, each >= 1e6 x the round-off bound (measured 4e-4 and 3e-5:
  // the Shepard sums of both are ~1 in the interior, so the mismatch shows
  // mostly near the walls and through the 1 % density perturbation):
  // gather (s_i) with kernel width 1.1 h, scatter with h;
  EXPECT_GT(residual(coupling_pairs(dem, c.fluid.x, c.box, 1.1 * c.h), rho, pairs), 1e-6);
  // s_i from the summation density, scatter divided by the perturbed one.
  EXPECT_GT(residual(pairs, c.fluid.rho, pairs), 1e-6);
}

// (4) A DEM particle with no SPH neighbour within 2h: NumericalError naming it.
TEST(CouplingExchange, NoFluidNeighbourThrowsNamingParticle) {
  const FluidCell c = make_cell();
  const std::vector<Vec3> dem = {Vec3(0.0, 1e-5, 1e-5), Vec3(0.5 * c.box.gap + 2.5 * c.h, 1e-5, 1e-5)};
  const auto pairs = coupling_pairs(dem, c.fluid.x, c.box, c.h);
  const std::vector<double> eps(c.fluid.size(), 1.0);
  try {
    shepard_interpolate(dem.size(), pairs, c.mass, c.fluid.rho, c.fluid.v, eps);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("DEM particle 1 "), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(shepard_interpolate(1, pairs, c.mass, c.fluid.rho, c.fluid.v, eps));
}

}  // namespace
}  // namespace mrf
