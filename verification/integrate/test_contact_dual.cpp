// The two solvers of the implicit contact step (scene/dem_model.hpp):
// the force (dual) form of integrate/contact_dual.hpp and the position
// (primal) form of integrate/implicit_contact.hpp solve the same backward
// Euler equations, so at tight tolerances they give the same trajectory.
// Checked on the small scene at the real modulus of iron (hundreds of
// contacts, chains ending on overlapping wall spheres, contacts made and
// broken), over fixed steps 3x and 9x the explicit contact limit. Also the
// two-stage candidate search equals the search over the whole Verlet list.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <cstdio>
#include <string>
#include <vector>

#include "mrf/integrate/contact_dual.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {
namespace {

struct Small {
  SceneConfig config;
  DemParams p;
};

Small small() {
  const LoadedScene s =
      load_scene(MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml", {"numerics.threads=1"});
  return {s.config, dem_params(s.config)};
}

DemModel implicit_model(const Small& s, double dt, ContactFormulation f, bool fixed) {
  DemModel m(build_shear_cell(s.config), s.p, IntegratorId::implicit, dt);
  ImplicitOptions o;
  o.formulation = f;
  o.fixed_step = fixed;
  o.newton_tol_over_radius = 1e-11;
  o.linear_rtol = 1e-12;
  o.max_newton = 200;  // the primal form needs many iterations at large steps
  m.set_implicit_options(o);
  return m;
}

double max_distance_over_radius(const DemModel& a, const DemModel& b) {
  double e = 0;
  const auto& xa = a.cell().free.x;
  const auto& xb = b.cell().free.x;
  for (std::size_t i = 0; i < xa.size(); ++i) e = std::max(e, a.cell().box.min_image(xa[i] - xb[i]).norm());
  return e / a.params().radius;
}

TEST(ContactDual, FixedStepsEqualThePrimalSolve) {
  const Small s = small();
  const double dt = 3.0 * smallest(dem_limits(s.p, s.config.gap, IntegratorId::verlet_exp));
  DemModel dual = implicit_model(s, dt, ContactFormulation::dual, true);
  DemModel primal = implicit_model(s, dt, ContactFormulation::primal, true);
  double moved = 0;
  const auto x_start = dual.cell().free.x;
  for (int n = 0; n < 200; ++n) {
    dual.step();
    primal.step();
  }
  for (std::size_t i = 0; i < x_start.size(); ++i)
    moved = std::max(moved, dual.cell().box.min_image(dual.cell().free.x[i] - x_start[i]).norm() / s.p.radius);
  const double diff = max_distance_over_radius(dual, primal);
  std::printf("200 steps of %.3e s: particles moved up to %.3f R, dual - primal %.2e R, max overlap %.2e R\n", dt,
              moved, diff, dual.sums().max_overlap / s.p.radius);
  EXPECT_GT(moved, 0.1) << "the steps must move the particles";
  EXPECT_GT(dual.sums().max_overlap, 0.0) << "the steps must make contacts";
  EXPECT_LT(diff, 1e-6);
}

TEST(ContactDual, LargeFixedStepsEqualThePrimalSolve) {
  // Steps of 5e-8 s, 9x the verlet_exp contact limit (the primal form fails to
  // converge at 1e-7 s, the mean error-controlled step, in 200 iterations):
  // contacts are made and broken within a step.
  const Small s = small();
  const double dt = 5e-8;
  DemModel dual = implicit_model(s, dt, ContactFormulation::dual, true);
  DemModel primal = implicit_model(s, dt, ContactFormulation::primal, true);
  for (int n = 0; n < 30; ++n) {
    ASSERT_NO_THROW(dual.step()) << "dual, step " << n;
    ASSERT_NO_THROW(primal.step()) << "primal, step " << n;
  }
  const double diff = max_distance_over_radius(dual, primal);
  std::printf("30 steps of %.1e s: dual - primal %.2e R; Newton %ld vs %ld\n", dt, diff,
              dual.implicit_counters().newton_iterations, primal.implicit_counters().newton_iterations);
  EXPECT_LT(diff, 1e-6);
}

TEST(ContactDual, TwoStageCandidateSearchEqualsTheFullSearch) {
  const Small s = small();
  DemModel m = implicit_model(s, smallest(dem_limits(s.p, s.config.gap, IntegratorId::implicit)),
                              ContactFormulation::dual, false);
  for (int n = 0; n < 100; ++n) m.step();
  const auto& c = m.cell();
  const double margin = 0.2 * s.p.radius;
  std::vector<ContactPair> full, near, staged;
  contact_candidates(m.lists(), c.free.x, c.walls, c.box, s.p.radius, margin, full);
  // The near list as the model keeps it: built a while ago (here at the
  // positions 1 R of travel back is emulated by a reach 1 R larger), filtered now.
  near_pairs(m.lists().ff, c.free.x, c.box, 3.2 * s.p.radius, near);
  contact_candidates(near, m.lists().fw, c.free.x, c.walls, c.box, s.p.radius, margin, staged);
  std::printf("%zu candidates; near list %zu of %zu free-free pairs\n", full.size(), near.size(),
              m.lists().ff.k.size());
  auto key = [](const ContactPair& a, const ContactPair& b) {
    return std::tie(a.wall, a.i, a.k) < std::tie(b.wall, b.i, b.k);
  };
  std::sort(full.begin(), full.end(), key);
  std::sort(staged.begin(), staged.end(), key);
  ASSERT_EQ(full.size(), staged.size());
  for (std::size_t n = 0; n < full.size(); ++n) {
    EXPECT_EQ(full[n].i, staged[n].i);
    EXPECT_EQ(full[n].k, staged[n].k);
    EXPECT_EQ(full[n].wall, staged[n].wall);
  }
  EXPECT_LT(near.size(), m.lists().ff.k.size() / 2) << "the near list should be much shorter than the dipole list";
}

// The incomplete-Cholesky preconditioner of the dual CG (ContactDual::
// Preconditioner): on the small scene at the real modulus of iron (chains,
// branches and loops of contacts), fixed steps solved at a tight tolerance
// give the same trajectory with IC(0) as with Jacobi, in far fewer CG
// iterations. (The coupled models use it by default: there a product
// sweeps every DEM-SPH pair.)
TEST(ContactDual, IncompleteCholeskyGivesTheJacobiTrajectoryInFewerIterations) {
  const Small s = small();
  const double dt = 9.0 * smallest(dem_limits(s.p, s.config.gap, IntegratorId::verlet_exp));
  auto model = [&](ContactDual::Preconditioner p) {
    DemModel m(build_shear_cell(s.config), s.p, IntegratorId::implicit, dt);
    ImplicitOptions o;
    o.fixed_step = true;
    o.newton_tol_over_radius = 1e-11;
    o.linear_rtol = 1e-12;
    o.max_newton = 200;
    o.dual_preconditioner = p;
    m.set_implicit_options(o);
    return m;
  };
  DemModel ic = model(ContactDual::Preconditioner::incomplete_cholesky);
  DemModel jac = model(ContactDual::Preconditioner::jacobi);
  for (int n = 0; n < 100; ++n) {
    ASSERT_NO_THROW(ic.step()) << "IC(0), step " << n;
    ASSERT_NO_THROW(jac.step()) << "Jacobi, step " << n;
  }
  const double diff = max_distance_over_radius(ic, jac);
  const long cg_ic = ic.implicit_counters().linear_iterations, cg_j = jac.implicit_counters().linear_iterations;
  std::printf("100 steps of %.2e s: IC(0) - Jacobi %.2e R; CG iterations %ld vs %ld (Newton %ld vs %ld)\n", dt, diff,
              cg_ic, cg_j, ic.implicit_counters().newton_iterations, jac.implicit_counters().newton_iterations);
  EXPECT_GT(ic.sums().max_overlap, 0.0) << "the steps must make contacts";
  EXPECT_LT(diff, 1e-10) << "both solves converge to 1e-11 R";
  EXPECT_LT(2 * cg_ic, cg_j) << "IC(0) must at least halve the CG iterations";
}


// A uniform shared fluid: C_ij = c for every pair (what one kernel gives
// particles far closer than h), enough to test the coupled preconditioner.
class UniformCoupling final : public MobilityCoupling {
 public:
  explicit UniformCoupling(double c) : c_(c) {}
  void add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
           const std::vector<std::uint32_t>* rows) override {
    Vec3 sum = Vec3::Zero();
    for (const Vec3& v : f) sum += v;
    if (rows) {
      for (std::uint32_t i : *rows) y[i] += scale * c_ * sum;
    } else {
      for (Vec3& v : y) v += scale * c_ * sum;
    }
  }
  double diagonal(std::size_t) const override { return c_; }
  double coupling(std::size_t, std::size_t) const override { return c_; }

 private:
  double c_;
};

// One sphere pressed between two walls by b, in a fluid whose response to
// the walls' unbalanced push is 50x the drag's mobility (s c = 50 mob), each
// Newton solve converged to 1e-12 R.
struct SphereBetweenWalls {
  double r = 1e-6, k = 1e4, mob = 1e-3, c = 5e4, s = 1e-6;
  Box box{10 * r, 10 * r, 10 * r};
  WallParticles walls;
  std::vector<ContactPair> pairs = {{0, 0, true}, {0, 1, true}};
  std::vector<Vec3> x0 = {Vec3::Zero()}, b = {Vec3(2e-3 * r, 0, 0)};
  SphereBetweenWalls() {
    walls.x = {Vec3(-1.99 * r, 0, 0), Vec3(1.995 * r, 0, 0)};
    walls.side = {-1, 1};
  }
  // y and the force on the sphere
  NewtonResult solve(ContactDual& dual, MobilityCoupling& fluid, std::vector<Vec3>& y, Vec3& f) const {
    NewtonOptions opt;
    opt.tol = 1e-12 * r;
    opt.max_iterations = 50;
    opt.linear_rtol = 1e-12;
    const NewtonResult res = dual.solve(pairs, b, x0, walls, walls, box, r, k, {mob}, &fluid, s, opt, y);
    std::vector<Vec3> forces(1, Vec3::Zero());
    dual.add_forces(pairs, forces);
    f = forces[0];
    return res;
  }
};

// Both wall contacts act on the same sphere, so s C enters their
// off-diagonal entry; IC(0) with it is the exact factor and each Newton
// solve needs one CG iteration (with the coupling on the diagonal only, as
// before, it needs two). The forces that come out balance the step's
// equation and the Hertz law.
TEST(ContactDual, CoupledWallContactsOfOneSphereFactorExactly) {
  const SphereBetweenWalls sw;
  UniformCoupling fluid(sw.c);
  ContactDual dual;
  dual.set_preconditioner(ContactDual::Preconditioner::incomplete_cholesky);
  std::vector<Vec3> y;
  Vec3 f;
  const NewtonResult res = sw.solve(dual, fluid, y, f);
  ASSERT_TRUE(res.converged) << "last correction " << res.last_correction;
  EXPECT_LE(res.linear_iterations, res.iterations - 1) << "one CG iteration per Newton solve";
  // y = b + (mob + s c) f, and each force is the Hertz force of its overlap
  const double r = sw.r, k = sw.k;
  EXPECT_NEAR(y[0].x(), sw.b[0].x() + (sw.mob + sw.s * sw.c) * f.x(), 1e-9 * r);
  const double left = 2 * r - (y[0].x() - sw.walls.x[0].x()), right = 2 * r - (sw.walls.x[1].x() - y[0].x());
  EXPECT_GT(left, 0.0);
  EXPECT_GT(right, 0.0);
  EXPECT_NEAR(f.x(), k * std::pow(left, 1.5) - k * std::pow(right, 1.5), 1e-9 * k * std::pow(left, 1.5));
}

// A coupling whose Jacobian is a cruder C (c_J = 0.6 c): the Newton
// iteration must take its residuals with C itself and its linear solves with
// C_J, so it lands on the same forces as with the exact Jacobian, the step's
// equation holding with C. Taking the residual with C_J would break
// y = b + (mob + s c) f by 0.4 s c f, 20x the drag part.
class CrudeJacobianCoupling final : public MobilityCoupling {
 public:
  explicit CrudeJacobianCoupling(double c) : exact_(c), crude_(0.6 * c) {}
  void add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
           const std::vector<std::uint32_t>* rows) override {
    ++adds;
    exact_.add(f, scale, y, rows);
  }
  void add_jacobian(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                    const std::vector<std::uint32_t>* rows) override {
    ++jacobian_adds;
    crude_.add(f, scale, y, rows);
  }
  double diagonal(std::size_t i) const override { return exact_.diagonal(i); }
  double coupling(std::size_t i, std::size_t k) const override { return exact_.coupling(i, k); }
  long adds = 0, jacobian_adds = 0;

 private:
  UniformCoupling exact_, crude_;
};

TEST(ContactDual, AnApproximateJacobianConvergesToTheSameForces) {
  const SphereBetweenWalls sw;
  UniformCoupling exact(sw.c);
  CrudeJacobianCoupling crude(sw.c);
  std::vector<Vec3> y_exact, y_crude;
  Vec3 f_exact, f_crude;
  ContactDual a, d;
  const NewtonResult ra = sw.solve(a, exact, y_exact, f_exact);
  const NewtonResult rd = sw.solve(d, crude, y_crude, f_crude);
  ASSERT_TRUE(ra.converged);
  ASSERT_TRUE(rd.converged) << "last correction " << rd.last_correction;
  EXPECT_GT(crude.jacobian_adds, 0) << "the linear solves apply C_J";
  EXPECT_GT(crude.adds, 0) << "the residuals apply C";
  EXPECT_GT(rd.iterations, ra.iterations) << "a cruder Jacobian converges more slowly";
  EXPECT_NEAR(y_crude[0].x(), sw.b[0].x() + (sw.mob + sw.s * sw.c) * f_crude.x(), 1e-9 * sw.r);
  EXPECT_NEAR(f_crude.x(), f_exact.x(), 1e-6 * std::abs(f_exact.x()));  // both to 1e-12 R in overlap
  EXPECT_NEAR(y_crude[0].x(), y_exact[0].x(), 1e-11 * sw.r);
}

// The solve's passes run on threads by blocks of pairs and of spheres, each
// sphere's terms summed in the order of the serial pass over the contacts:
// on the paper cell (thousands of active contacts, enough for the threaded
// passes), 2 and 3 threads give the 1-thread solve bit for bit, and so
// does a team smaller than asked (2 threads asked, OpenMP giving 1: blocks
// planned for 2), for model 1's mobility (Jacobi, a pass over the contacts
// on one thread) and a coupled one (IC(0), whose assembly reads the sphere
// index on one thread too).
TEST(ContactDual, ThreadsGiveTheSerialSolveBitForBit) {
  const LoadedScene sc =
      load_scene(MRF_SOURCE_DIR "/experiments/scenes/paper_dem_stokes.toml", {"numerics.threads=1"});
  const DemParams p = dem_params(sc.config);
  DemModel m(build_shear_cell(sc.config), p, IntegratorId::implicit,
             smallest(dem_limits(p, sc.config.gap, IntegratorId::implicit)));
  for (int n = 0; n < 30; ++n) m.step();
  const ShearCell& c = m.cell();
  std::vector<ContactPair> pairs;
  contact_candidates(m.lists(), c.free.x, c.walls, c.box, p.radius, 0.2 * p.radius, pairs);
  // every sphere pushed by 0.05 R in a direction of its own
  std::vector<Vec3> b = c.free.x;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const double t = static_cast<double>(i);
    b[i] += 0.05 * p.radius * Vec3(std::cos(t), std::sin(1.7 * t), std::cos(2.3 * t)).normalized();
  }
  const std::vector<double> mob(b.size(), 1e-6 / p.gamma);
  NewtonOptions opt;
  opt.tol = 1e-6 * p.radius;
  opt.max_iterations = 30;
  opt.linear_rtol = 1e-2;
  UniformCoupling fluid(0.01 / p.gamma);  // s C = 0.01 of the drag mobility
  for (const bool coupled : {false, true}) {
    constexpr int runs = 4;  // 1, 2 and 3 threads; 2 asked with a team of 1
    std::vector<Vec3> y[runs];
    NewtonResult res[runs];
    std::vector<Vec3> f[runs];
    for (int t = 0; t < runs; ++t) {
      const int saved = omp_get_max_threads(), saved_levels = omp_get_max_active_levels();
      omp_set_num_threads(t < 3 ? t + 1 : 2);
      if (t == 3) omp_set_max_active_levels(0);  // every team of one thread
      ContactDual dual;
      res[t] = dual.solve(pairs, b, c.free.x, c.walls, c.walls, c.box, p.radius, p.hertz_k, mob,
                          coupled ? &fluid : nullptr, 1e-6, opt, y[t]);
      omp_set_num_threads(saved);
      omp_set_max_active_levels(saved_levels);
      f[t].assign(b.size(), Vec3::Zero());
      dual.add_forces(pairs, f[t]);
    }
    std::size_t touching = 0;
    std::vector<char> in_contact(b.size(), 0);
    for (const ContactPair& pc : pairs) {
      if (c.box.min_image(y[0][pc.i] - (pc.wall ? c.walls.x[pc.k] : y[0][pc.k])).norm() >= 2 * p.radius) continue;
      ++touching;
      in_contact[pc.i] = 1;
      if (!pc.wall) in_contact[pc.k] = 1;
    }
    const auto spheres = static_cast<std::size_t>(std::count(in_contact.begin(), in_contact.end(), 1));
    std::printf("%s: %zu candidates, %zu contacts on %zu spheres; Newton %d, CG %ld, converged %d\n",
                coupled ? "coupled, IC(0)" : "model 1, Jacobi", pairs.size(), touching, spheres, res[0].iterations,
                res[0].linear_iterations, res[0].converged ? 1 : 0);
    EXPECT_GT(spheres, 2048u) << "enough spheres in contact for the threaded passes";
    EXPECT_TRUE(res[0].converged);
    EXPECT_GE(res[0].iterations, 3) << "a solve of several Newton iterations";
    for (int t = 1; t < runs; ++t) {
      EXPECT_EQ(res[0].iterations, res[t].iterations) << "run " << t;
      EXPECT_EQ(res[0].linear_iterations, res[t].linear_iterations) << "run " << t;
      EXPECT_EQ(res[0].worst, res[t].worst) << "run " << t;
      EXPECT_EQ(res[0].last_correction, res[t].last_correction) << "run " << t;
      for (std::size_t i = 0; i < b.size(); ++i) {
        ASSERT_EQ(y[0][i], y[t][i]) << "sphere " << i << ", run " << t;
        ASSERT_EQ(f[0][i], f[t][i]) << "sphere " << i << ", run " << t;
      }
    }
  }
}

}  // namespace
}  // namespace mrf
