// The fluid-only Couette run from a scene (the `mrf run` entry point): the
// paper shear cell at dx = 10 um with real oil, implicit viscosity chosen
// automatically, steady stress eta gdot; scene errors name their key.
#include <gtest/gtest.h>

#include "mrf/error.hpp"
#include "mrf/scene/fluid_only.hpp"

namespace mrf {
namespace {

SceneConfig paper_scene() {
  SceneConfig s;
  s.model = ModelId::demsph_stokes;
  s.gap = 150e-6;
  s.ly = 50e-6;
  s.lz = 120e-6;
  s.viscosity = 0.1;
  s.fluid_density = 1000;
  s.sph_spacing = 10e-6;
  s.shear_rate = 100;
  return s;
}

TEST(SphCouetteScene, PaperCellReachesEtaGdot) {
  const SceneConfig s = paper_scene();
  const CouetteSphResult r = run_couette_sph(s, 0.5 * s.gap * s.gap * s.fluid_density / s.viscosity);
  EXPECT_TRUE(r.implicit_viscosity);  // the viscous limit binds for real oil
  EXPECT_EQ(r.n_fluid, 15u * 5u * 12u);
  EXPECT_NEAR(r.shear_stress / r.steady_stress, 1.0, 0.01);
  EXPECT_LT(r.profile_error, 1e-3);
  EXPECT_LT(r.max_density_deviation, 0.01);
  EXPECT_NEAR(r.reynolds, 0.0225, 1e-6);
  RecordProperty("steps", std::to_string(r.steps));
  RecordProperty("wall_seconds", std::to_string(r.wall_seconds));
}

TEST(SphCouetteScene, RejectsParticlesAndDemModel) {
  SceneConfig s = paper_scene();
  s.volume_fraction = 0.3;
  EXPECT_THROW(run_couette_sph(s, 1e-5), InputError);
  s = paper_scene();
  s.model = ModelId::dem_stokes;
  EXPECT_THROW(run_couette_sph(s, 1e-5), InputError);
  s = paper_scene();
  s.integrator = IntegratorId::verlet_exp;
  s.dt = 1e-6;  // 5x the explicit viscous limit
  try {
    run_couette_sph(s, 1e-5);
    FAIL() << "dt above the limit accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "numerics.dt");
  }
}

}  // namespace
}  // namespace mrf
