// The two solvers of the implicit contact step (scene/dem_model.hpp):
// the force (dual) form of integrate/contact_dual.hpp and the position
// (primal) form of integrate/implicit_contact.hpp solve the same backward
// Euler equations, so at tight tolerances they give the same trajectory.
// Checked on the small scene at the real modulus of iron (hundreds of
// contacts, chains ending on overlapping wall spheres, contacts made and
// broken), over fixed steps 3x the explicit contact limit and over
// error-controlled steps. Also the two-stage candidate search equals the
// search over the whole Verlet list.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

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
  const double dt = 3.0 * smallest(dem_limits(s.p, s.config, IntegratorId::verlet_exp));
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

TEST(ContactDual, ErrorControlledStepsEqualThePrimalSolve) {
  const Small s = small();
  const double bound = smallest(dem_limits(s.p, s.config, IntegratorId::implicit));
  DemModel dual = implicit_model(s, bound, ContactFormulation::dual, false);
  DemModel primal = implicit_model(s, bound, ContactFormulation::primal, false);
  // 20 steps: later one solver may need a retry the other does not (a Newton
  // failure of the primal form at this tolerance), and the paths part.
  for (int n = 0; n < 20; ++n) {
    dual.step();
    primal.step();
    ASSERT_NEAR(dual.time(), primal.time(), 1e-8 * primal.time()) << "the same steps are accepted, step " << n;
  }
  const double diff = max_distance_over_radius(dual, primal);
  std::printf("20 error-controlled steps to t = %.3e s: dual - primal %.2e R; Newton %ld vs %ld\n", dual.time(), diff,
              dual.implicit_counters().newton_iterations, primal.implicit_counters().newton_iterations);
  EXPECT_LT(diff, 1e-6);
}

TEST(ContactDual, TwoStageCandidateSearchEqualsTheFullSearch) {
  const Small s = small();
  DemModel m = implicit_model(s, smallest(dem_limits(s.p, s.config, IntegratorId::implicit)),
                              ContactFormulation::dual, false);
  for (int n = 0; n < 100; ++n) m.step();
  const auto& c = m.cell();
  const double margin = 0.2 * s.p.radius;
  std::vector<ContactPair> full, near, staged;
  contact_candidates(m.lists(), c.free.x, c.walls, c.box, s.p.radius, margin, full);
  near_pairs(m.lists(), c.box, 2.0 * s.p.radius + margin + m.lists().skin, near);
  contact_candidates(near, m.lists().fw, c.free.x, c.walls, c.box, s.p.radius, margin, staged);
  std::printf("%zu candidates; near list %zu of %zu free-free pairs\n", full.size(), near.size(),
              m.lists().ff.k.size());
  ASSERT_EQ(full.size(), staged.size());
  for (std::size_t n = 0; n < full.size(); ++n) {
    EXPECT_EQ(full[n].i, staged[n].i);
    EXPECT_EQ(full[n].k, staged[n].k);
    EXPECT_EQ(full[n].wall, staged[n].wall);
  }
  EXPECT_LT(near.size(), m.lists().ff.k.size() / 2) << "the near list should be much shorter than the dipole list";
}

}  // namespace
}  // namespace mrf
