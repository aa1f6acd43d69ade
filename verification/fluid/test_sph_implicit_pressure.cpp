// Backward Euler on pressure and viscosity together (fluid/implicit_fluid.hpp):
// the system is symmetric positive definite, its density rows are the
// first-order change of the summation density, start-up Couette agrees with
// the explicit solver and with the exact profile, the error falls at least
// linearly with dt, and the step is stable far beyond the acoustic and
// viscous limits; the products on threads (a gather per particle) give the
// serial scatter's results bit for bit.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>

#include "mrf/error.hpp"
#include "mrf/integrate/pcg.hpp"
#include "sph_channel.hpp"

namespace mrf::test {
namespace {

constexpr double k_gdot = 100.0;

// A channel with its particles displaced by up to 10 % of dx, random
// velocities of the wall speed's order and, if `porous`, porosities in
// (0.6, 1): no lattice symmetry left to hide an error.
FluidCell disordered(bool porous, std::mt19937& rng) {
  FluidCell c = channel(10, k_gdot, 0.0, k_eta, 0.0, 6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double dx = c.params.spacing, v0 = 0.5 * k_gdot * c.box.gap;
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    c.fluid.x[a] += 0.1 * dx * Vec3(u(rng), u(rng), u(rng));
    c.fluid.v[a] = v0 * Vec3(u(rng), u(rng), u(rng));
  }
  if (porous) {
    c.fluid.eps.resize(c.fluid.size());
    for (double& e : c.fluid.eps) e = 0.8 + 0.2 * u(rng);
  }
  refresh(c);
  return c;
}

std::vector<Vec3> random_field(std::size_t n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::vector<Vec3> x(n);
  for (Vec3& v : x) v = Vec3(g(rng), g(rng), g(rng));
  return x;
}

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) { return vector_dot(a, b); }

TEST(SphImplicitPressure, SystemIsSymmetricPositiveDefinite) {
  std::mt19937 rng(7);
  for (bool porous : {false, true}) {
    const FluidCell c = disordered(porous, rng);
    // 20x the acoustic step: the pressure rows dominate the identity
    const double dt = 20 * 0.25 * c.h / c.c0;
    const ImplicitFluidSystem sys(c, dt, SphImplicit::pressure_viscosity);
    for (int trial = 0; trial < 5; ++trial) {
      const auto x = random_field(c.fluid.size(), rng), y = random_field(c.fluid.size(), rng);
      std::vector<Vec3> ax, ay;
      sys.apply(x, ax);
      sys.apply(y, ay);
      EXPECT_NEAR(dot(y, ax), dot(x, ay), 1e-12 * std::sqrt(dot(ax, ax) * dot(y, y))) << "porous " << porous;
      // A = I + (PSD): x.Ax >= x.x, and the pressure part is not negligible
      EXPECT_GT(dot(x, ax), 2.0 * dot(x, x)) << "porous " << porous;
    }
    // the Jacobi diagonal is the operator's: e_a . A e_a
    for (std::size_t a : {std::size_t{0}, c.fluid.size() / 2}) {
      for (int k = 0; k < 3; ++k) {
        std::vector<Vec3> e(c.fluid.size(), Vec3::Zero()), ae;
        e[a][k] = 1.0;
        sys.apply(e, ae);
        EXPECT_NEAR(ae[a][k], sys.diagonal()[a][k], 1e-12 * ae[a][k]);
      }
    }
  }
}

TEST(SphImplicitPressure, DensityRowsAreTheFirstOrderChangeOfTheSummationDensity) {
  // Move every particle (and the walls) by dt v and recompute the summation
  // density: the rows predict the change with a remainder of order dt^2.
  std::mt19937 rng(11);
  const FluidCell c0 = disordered(false, rng);
  const double base = 0.05 * c0.params.spacing / (0.5 * k_gdot * c0.box.gap);  // moves ~5 % of dx
  std::vector<double> remainder;
  for (double dt : {base, base / 2, base / 4}) {
    const ImplicitFluidSystem sys(c0, dt, SphImplicit::pressure_viscosity);
    const std::vector<double> predicted = sys.density_change(c0.fluid.v);
    FluidCell c = c0;
    for (std::size_t a = 0; a < c.fluid.size(); ++a) c.fluid.x[a] += dt * c.fluid.v[a];
    for (std::size_t w = 0; w < c.wall.size(); ++w) c.wall.x[w] += dt * c.wall.v[w];
    for (auto& x : c.fluid.x) c.box.wrap(x);
    for (auto& x : c.wall.x) c.box.wrap(x);
    refresh(c);
    double err = 0, size = 0;
    for (std::size_t a = 0; a < c.fluid.size(); ++a) {
      const double actual = c.fluid.rho[a] - c0.fluid.rho[a];
      err = std::max(err, std::abs(predicted[a] - actual));
      size = std::max(size, std::abs(actual));
    }
    EXPECT_LT(err, 0.1 * size) << "dt " << dt;
    remainder.push_back(err);
  }
  const double order = std::log2(remainder[1] / remainder[2]);
  EXPECT_NEAR(order, 2.0, 0.3) << remainder[0] << " " << remainder[1] << " " << remainder[2];
  RecordProperty("remainder_order", std::to_string(order));
}

void run_implicit(FluidCell& c, double t, double dt) {
  while (c.time < t * (1 - 1e-12)) step_implicit(c, std::min(dt, t - c.time), SphImplicit::pressure_viscosity);
}

TEST(SphImplicitPressure, AgreesWithExplicitOnStartupCouette) {
  FluidCell e = channel(15, k_gdot, 0.0), i = channel(15, k_gdot, 0.0);
  const double dt = explicit_dt(e);
  for (double t : {0.05, 0.3}) {
    run_to(e, t * k_t_visc, dt, false);
    run_implicit(i, t * k_t_visc, dt);
    EXPECT_LT(velocity_difference(i, e), t < 0.1 ? 1e-2 : 1e-4) << "t/T = " << t;
  }
  EXPECT_NEAR(wall_shear_stress(i).tau, k_eta * k_gdot, 1e-3 * k_eta * k_gdot);
}

// c0 = 20 m/s: the acoustic limit 0.25 h/c0 = 1.6e-7 s is 1400x shorter
// than the diffusion time L^2/nu, so steps of 10-40x it are still short
// enough to follow the start-up.
constexpr double k_fast_sound = 20.0;

// Random velocities of 1 % of the wall speed: sound to be damped or amplified.
void stir(FluidCell& c, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double v = 0.01 * 0.5 * k_gdot * c.box.gap;
  for (Vec3& x : c.fluid.v) x += v * Vec3(u(rng), u(rng), u(rng));
}

TEST(SphImplicitPressure, StableFarBeyondTheAcousticLimitAndFirstOrderInTime) {
  // Stirred start-up Couette with steps of 5-20x the acoustic limit (2-8x
  // the viscous one) against the same scheme at 1.25x: stable, first order
  // in dt; the steady profile and wall stress exact.
  const auto run = [](double factor, double t) {
    FluidCell c = channel(15, k_gdot, 0.0, k_eta, k_fast_sound);
    stir(c, 3);
    const double dt = factor * binding(stability_limits(c, SphImplicit::viscosity)).dt;
    run_implicit(c, t, dt);
    return c;
  };
  const double t = 0.2 * k_t_visc;
  const FluidCell ref = run(1.25, t);
  std::vector<double> errors;
  const double factors[] = {20.0, 10.0, 5.0};
  for (double factor : factors) {
    FluidCell c = run(factor, t);
    errors.push_back(velocity_difference(c, ref));
    const double dt = factor * binding(stability_limits(c, SphImplicit::viscosity)).dt;
    ASSERT_LT(dt, binding(stability_limits(c, SphImplicit::pressure_viscosity)).dt);
    EXPECT_THROW(check_time_step(c, dt, SphImplicit::viscosity), InputError);
    run_implicit(c, 0.6 * k_t_visc, dt);
    EXPECT_LT(profile_error(c, couette_exact(c, c.time)), 1e-4) << factor << "x";
    EXPECT_LT(density_stats(c).max_abs_error, 0.01) << factor << "x";
    EXPECT_NEAR(wall_shear_stress(c).tau, k_eta * k_gdot, 1e-3 * k_eta * k_gdot) << factor << "x";
  }
  // The order on the two coarser intervals (the reference's own error at
  // 1.25x shifts the finest point most). Backward Euler is first order; the
  // impulsive start makes the observed order 1.4-1.5 at these steps (the
  // same without the stirring): assert first order or better, and below 2.
  const double order = std::log(errors[0] / errors[1]) / std::log(2.0);
  EXPECT_GT(order, 0.9) << errors[0] << " " << errors[1] << " " << errors[2];
  EXPECT_LT(order, 1.9) << errors[0] << " " << errors[1] << " " << errors[2];
  RecordProperty("time_order", std::to_string(order));
}


// Above 4096 pairs the products gather per particle on threads, each
// particle's terms in the serial scatter's order: the product, the
// right-hand side and the walls' push (both through the pressure scatter)
// are the same bit for bit on 1, 2 and 3 threads, for both sets of terms.
TEST(SphImplicitPressure, ProductsTheSameOnAnyNumberOfThreads) {
  std::mt19937 rng(19);
  const FluidCell c = disordered(true, rng);
  ASSERT_GT(c.pairs.fluid_fluid.size(), 2u * 4096u);
  const double dt = 20 * 0.25 * c.h / c.c0;
  const std::vector<Vec3> x = random_field(c.fluid.size(), rng);
  const int saved = omp_get_max_threads();
  for (SphImplicit terms : {SphImplicit::viscosity, SphImplicit::pressure_viscosity}) {
    auto run = [&](int t) {
      omp_set_num_threads(t);
      const ImplicitFluidSystem sys(c, dt, terms);
      std::vector<Vec3> out;
      sys.apply(x, out);
      const std::vector<Vec3> rhs = sys.rhs(x);
      out.insert(out.end(), rhs.begin(), rhs.end());
      out.push_back(sys.wall_push(x));
      return out;
    };
    const std::vector<Vec3> one = run(1);
    for (int t : {2, 3}) {
      const std::vector<Vec3> many = run(t);
      ASSERT_EQ(many.size(), one.size());
      for (std::size_t a = 0; a < one.size(); ++a)
        ASSERT_EQ(many[a], one[a]) << to_string(terms) << ", " << t << " threads, entry " << a;
    }
  }
  omp_set_num_threads(saved);
}

}  // namespace
}  // namespace mrf::test
