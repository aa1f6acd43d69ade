// Hertz contact, REFERENCE.md §2: force law, energy, and the head-on elastic
// impact of TEST 2.1 run through the model's own integrator.
#include <gtest/gtest.h>

#include "mrf/forces/hertz.hpp"
#include "mrf/scene/dem_model.hpp"
#include "support/fit_order.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, Y = 200e9, nu = 0.3, rho = 7800;

TEST(Hertz, StiffnessIsPaperFormForIdenticalSpheres) {
  // k = (2/3) Y/(1 - nu^2) sqrt(R/2)
  EXPECT_NEAR(hertz_stiffness(Y, nu, R, R), 2.0 / 3.0 * Y / (1 - nu * nu) * std::sqrt(R / 2),
              1e-6);
}

TEST(Hertz, ForceEnergyAndStiffness) {
  const double k = hertz_stiffness(Y, nu, R, R);
  const double h = 1e-9;
  EXPECT_DOUBLE_EQ(hertz_force(h, k), k * std::pow(h, 1.5));
  EXPECT_EQ(hertz_force(-h, k), 0.0);
  const double eps = 1e-13;
  EXPECT_NEAR((hertz_energy(h + eps, k) - hertz_energy(h - eps, k)) / (2 * eps), hertz_force(h, k),
              1e-6 * hertz_force(h, k));
  EXPECT_NEAR((hertz_force(h + eps, k) - hertz_force(h - eps, k)) / (2 * eps),
              hertz_local_stiffness(h, k), 1e-6 * hertz_local_stiffness(h, k));
  EXPECT_NEAR(hertz_overlap_under_load(hertz_force(h, k), k), h, 1e-12 * h);
}

TEST(Hertz, PairForceRepelsAlongSeparation) {
  const double k = hertz_stiffness(Y, nu, R, R);
  const Vec3 r(0.0, 3e-6, -3.9e-6);  // |r| < 2R
  const Vec3 f = hertz_pair_force(r, 2 * R, k);
  EXPECT_GT(f.dot(r), 0.0);
  EXPECT_NEAR(f.norm(), hertz_force(2 * R - r.norm(), k), 1e-12 * f.norm());
  EXPECT_EQ(hertz_pair_force(-r, 2 * R, k), Vec3(-f));
}

TEST(Hertz, ContactTimeNumbersOfReference) {
  const double k = hertz_stiffness(Y, nu, R, R);
  const double mstar = 0.5 * rho * sphere_volume(R);
  EXPECT_NEAR(hertz_contact_time(mstar, 1e-3, k), 6.090e-8, 0.001e-8);
  EXPECT_NEAR(hertz_max_overlap(mstar, 1e-3, k), 2.069e-11, 0.001e-11);
  EXPECT_NEAR(hertz_contact_time(mstar, 1e-2, k), 3.843e-8, 0.001e-8);
}

// Two free spheres, no field, (almost) no fluid, approaching head-on.
struct Impact {
  double restitution, contact_time;
};
Impact head_on_impact(double v0, double dt) {
  SceneConfig c;
  c.radius = R;
  c.density = rho;
  c.youngs_modulus = Y;
  c.poisson_ratio = nu;
  c.viscosity = 1e-15;  // tau_p ~ 1e7 s: no damping on the scale of the impact
  c.dipole_cutoff = 2 * R;
  ShearCell cell;
  cell.box = Box{1e-3, 1e-3, 1e-3};
  cell.free.x = {Vec3(-R - 0.5 * v0 * 4 * dt, 5e-4, 5e-4), Vec3(R + 0.5 * v0 * 4 * dt, 5e-4, 5e-4)};
  cell.free.v = {Vec3(0.5 * v0, 0, 0), Vec3(-0.5 * v0, 0, 0)};
  cell.free.f.assign(2, Vec3::Zero());
  DemModel model(cell, dem_params(c), IntegratorId::verlet_exp, dt);
  double t_in = -1, t_out = -1;
  double h_prev = 2 * R - (model.cell().free.x[1] - model.cell().free.x[0]).norm();
  for (int s = 0; s < 100000 && t_out < 0; ++s) {
    model.step();
    const double h = 2 * R - (model.cell().free.x[1] - model.cell().free.x[0]).norm();
    // linear interpolation of the crossing of h = 0
    if (h_prev <= 0 && h > 0) t_in = model.time() - dt * h / (h - h_prev);
    if (h_prev > 0 && h <= 0) t_out = model.time() - dt * h / (h - h_prev);
    h_prev = h;
  }
  for (int s = 0; s < 5; ++s) model.step();  // leave the contact fully
  const Vec3 vrel = model.cell().free.v[1] - model.cell().free.v[0];
  return {vrel.x() / v0, t_out - t_in};
}

TEST(Hertz, ElasticHeadOnImpactRestitutionAndDuration) {
  const double v0 = 1e-3;
  const double k = hertz_stiffness(Y, nu, R, R);
  const double tc = hertz_contact_time(0.5 * rho * sphere_volume(R), v0, k);
  const Impact imp = head_on_impact(v0, tc / 200);
  EXPECT_NEAR(imp.restitution, 1.0, 1e-3);
  EXPECT_NEAR(imp.contact_time / tc, 1.0, 0.01);
}

}  // namespace
}  // namespace mrf
