// The inertialess coupled scheme (scene/coupled_model.hpp, CoupledScheme::
// inertialess): v = u + F/gamma in the SPH carrier with implicit contacts.
// (1) A single sphere pushed through the fluid settles at the terminal slip
// of each drag law, within 1 % (Robinson, Ramaioli & Luding report ~1 % for
// SPH-DEM). (2) Momentum of fluid + walls is conserved to round-off on the
// small scene with DEM walls: the particles carry none, and what they pass to
// the fluid is exactly what their contacts with the walls push. (3) Two
// spheres pulled into contact in a sheared carrier: the fixed-step error
// against a fine-step reference falls at first order for IMEX Euler; BDF2 is
// more accurate and second order at first, until the first-order split with
// the explicit SPH step takes over.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mrf/coupling/drag_laws.hpp"
#include "mrf/coupling/exchange.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/coupled_model.hpp"
#include "support/fit_order.hpp"

namespace mrf {
namespace {

const std::string kSmall = MRF_SOURCE_DIR "/experiments/scenes/small_demsph_stokes.toml";

CoupledStepping inertialess(double dt_max, double dt_fluid, int order = 2, bool fixed = false) {
  CoupledStepping s;
  s.scheme = CoupledScheme::inertialess;
  s.dt_max = dt_max;
  s.dt_fluid = dt_fluid;
  s.implicit.order = order;
  s.implicit.fixed_step = fixed;
  if (fixed) s.implicit.newton_tol_over_radius = 1e-11;  // convergence tests: Newton far below the step error
  return s;
}

ShearCell cell_of(const SceneConfig& c, std::vector<Vec3> x) {
  ShearCell cell;
  cell.box = Box{c.gap, c.ly, c.lz};
  cell.free.x = std::move(x);
  cell.free.v.assign(cell.free.size(), Vec3::Zero());
  cell.free.f.assign(cell.free.size(), Vec3::Zero());
  return cell;
}

// One sphere (R = 2.5 um) pushed along z by F in fluid at rest between
// resting walls (as in test_coupled_model.cpp's settling test). The slip of
// its mean velocity over the last step against the fluid velocity
// interpolated at it, averaged over the same step (the fluid it drives
// accelerates), must be the terminal slip of the law.
double settle(CoupledDrag law, double& expect) {
  LoadedScene scene = load_scene(kSmall, {"particles.volume_fraction=0.0", "particles.magnetization=0.0",
                                          "drive.shear_rate=1e-9", "fluid.sound_speed=0.5"});
  const SceneConfig& c = scene.config;
  ShearCell cell = cell_of(c, {Vec3(0.0, 0.5 * c.ly, 0.5 * c.lz)});
  FluidCell fluid = build_coupled_fluid(c, cell);
  CoupledModel m(std::move(cell), dem_params(c), std::move(fluid), law, inertialess(5e-7, 5e-8));
  const Vec3 force(0.0, 0.0, 4.712e-8);  // Stokes terminal speed 1 cm/s
  m.set_body_force(force);
  m.set_stop_time(1.5e-5);
  auto fluid_at_particle = [&m] {
    const FluidCell& f = m.fluid();
    const auto pairs = coupling_pairs(m.cell().free.x, f.fluid.x, f.box, f.h);
    return shepard_interpolate(1, pairs, f.mass, f.fluid.rho, f.fluid.v, f.fluid.eps);
  };
  ShepardField before;
  while (m.time() < 1.5e-5 * (1 - 1e-12)) {
    before = fluid_at_particle();
    m.step();
  }
  const ShepardField sh = fluid_at_particle();
  expect = force.z() / stokes_coupled_drag_coefficient(c.radius, c.viscosity);
  if (law == CoupledDrag::di_felice) {
    const DiFeliceDrag dd{2.0 * c.radius, c.fluid_density, c.viscosity};
    for (int k = 0; k < 50; ++k) expect = force.z() / drag_coefficient(dd, expect, sh.eps[0]);
  }
  return (m.cell().free.v[0] - 0.5 * (before.u[0] + sh.u[0])).z();
}

TEST(CoupledInertialess, SingleParticleReachesTheTerminalSlipOfEachDragLaw) {
  for (CoupledDrag law : {CoupledDrag::stokes, CoupledDrag::di_felice}) {
    double expect = 0;
    const double slip = settle(law, expect);
    EXPECT_NEAR(slip, expect, 0.01 * expect) << (law == CoupledDrag::stokes ? "stokes" : "di_felice");
    RecordProperty(std::string(law == CoupledDrag::stokes ? "stokes" : "di_felice") + "_relative_error",
                   std::to_string(slip / expect - 1.0));
  }
}

// The small scene with its DEM walls, Mn = 1e-2: over 30 implicit steps the
// fluid's momentum changes by exactly the impulse of the SPH walls on it
// plus what the particles' wall contacts push (the particles are
// inertialess and carry none).
TEST(CoupledInertialess, MomentumOfFluidAndWallsConservedToRoundOff) {
  const LoadedScene scene = load_scene(kSmall, {"scene.model=\"demsph_dd\"", "numerics.integrator=\"implicit\""});
  BuiltModel b = build_model(scene);
  auto& m = dynamic_cast<CoupledModel&>(*b.model);
  ASSERT_EQ(m.scheme(), CoupledScheme::inertialess);
  const Vec3 p0 = m.momentum();
  const SceneConfig& c = scene.config;
  const double scale =
      m.fluid().mass * static_cast<double>(m.fluid().fluid.size()) * c.shear_rate * 0.5 * c.gap;
  for (int n = 0; n < 30; ++n) m.step();
  const Vec3 change = m.momentum() - p0;
  // 30 steps of ~4 SPH sub-steps with contact and dipole sums: round-off
  // of 1e-12 of the fluid's momentum at the wall speed (a lost term would be
  // of the order of the change, 1e-1 of it).
  EXPECT_LT((change - m.external_impulse()).norm(), 1e-12 * scale) << change.transpose();
  RecordProperty("momentum_drift_relative", std::to_string((change - m.external_impulse()).norm() / scale));
  EXPECT_GT(change.norm(), 1e-6 * scale);  // the balance is not trivially zero
  EXPECT_GT(m.cell().walls.size(), 0u);
}

// Two spheres head-to-tail along the field, 2.2 R apart, in a carrier
// sheared at 1e3 1/s: the dipole pull brings them into contact at ~3.5e-7 s
// (REFERENCE TEST 1.2), then the pair drifts with the flow. Fixed steps of
// 1e-7 ... 6.25e-9 s (one SPH sub-step each, so that the fluid's time error
// falls too) against 1/256 of the coarsest, each scheme against its own.
std::vector<Vec3> pair_run(int order, double dt, double t_end) {
  const LoadedScene scene = load_scene(kSmall, {"particles.volume_fraction=0.0", "drive.shear_rate=1e3"});
  const SceneConfig& c = scene.config;
  const double y = 0.5 * c.ly, z = 0.5 * c.lz, d = 1.1 * c.radius;
  ShearCell cell = cell_of(c, {Vec3(-d, y, z), Vec3(d, y, z)});
  FluidCell fluid = build_coupled_fluid(c, cell);
  CoupledModel m(std::move(cell), dem_params(c), std::move(fluid), CoupledDrag::stokes,
                 inertialess(dt, dt, order, true));
  const long n = std::lround(t_end / dt);
  for (long k = 0; k < n; ++k) m.step();
  return m.cell().free.x;
}

TEST(CoupledInertialess, PairIntoContactConvergesAtFirstOrder) {
  const double t_end = 1e-6, radius = 2.5e-6;
  const std::vector<double> steps{1e-7, 5e-8, 2.5e-8, 1.25e-8, 6.25e-9};
  std::vector<double> err1, err2;
  for (int order : {1, 2}) {
    const std::vector<Vec3> ref = pair_run(order, steps.front() / 256, t_end);
    ASSERT_LT((ref[1] - ref[0]).norm(), 2.0 * radius * (1 + 1e-3)) << "the pair must end in contact";
    for (double dt : steps) {
      const std::vector<Vec3> x = pair_run(order, dt, t_end);
      (order == 1 ? err1 : err2).push_back(((x[0] - ref[0]).norm() + (x[1] - ref[1]).norm()) / radius);
    }
  }
  for (std::size_t k = 0; k < steps.size(); ++k)
    std::printf("dt %.3g s: error / R  IMEX Euler %.3e  BDF2 %.3e\n", steps[k], err1[k], err2[k]);
  for (std::size_t k = 1; k < steps.size(); ++k) EXPECT_LT(err1[k], err1[k - 1]) << "dt " << steps[k];
  const test::OrderFit f1 = test::fit_order(steps, err1), f2 = test::fit_order(steps, err2);
  EXPECT_NEAR(f1.order, 1.0, 0.15);
  // BDF2 is several times more accurate and falls at second order at first
  // (its relative step and the carrier's path are second order: 1.9 over
  // the first two halvings here, where first order would give 1), then
  // slower as the first-order split with the explicit SPH step takes over
  // (BDF2 7.5e-8 R at 6e-9 s against IMEX Euler's 3.8e-6).
  for (std::size_t k = 0; k < steps.size(); ++k) EXPECT_LT(5 * err2[k], err1[k]) << "dt " << steps[k];
  EXPECT_GT(err2[0] / err2[2], std::pow(2.0, 2 * 1.7)) << "order 1.7 or more over the first two halvings";
  RecordProperty("observed_order_imex_euler", std::to_string(f1.order));
  RecordProperty("observed_order_bdf2", std::to_string(f2.order));
}

}  // namespace
}  // namespace mrf
