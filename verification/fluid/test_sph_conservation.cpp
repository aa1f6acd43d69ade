// Conservation and robustness of the SPH fluid: exact momentum balance of an
// explicit step, mass, density variation < 1 %, no wall crossing under a
// disturbed start, NaN detection, parameter validation and dt refusal.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/toml_scene.hpp"
#include "sph_channel.hpp"

namespace mrf::test {
namespace {

// A cell with a disturbed start: random velocities of 20 % of the wall speed.
FluidCell disturbed(double shear_rate, double body_force, std::uint64_t seed) {
  FluidCell c = channel(12, shear_rate, body_force);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 0.2 * 7.5e-3);
  for (Vec3& v : c.fluid.v) v = Vec3(n(rng), n(rng), n(rng));
  return c;
}

TEST(SphConservation, MomentumChangeEqualsWallPlusExternalForce) {
  // Pair terms are antisymmetric, so P(n+1) - P(n) = dt (F_walls + sum m a_ext + M f)
  // to round-off; a sign slip in any pair term breaks this.
  FluidCell c = disturbed(100.0, 50.0, 1);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  Vec3 ext = Vec3::Zero();
  for (Vec3& a : c.fluid.a_ext) ext += c.mass * (a = Vec3(u(rng), u(rng), u(rng)));
  for (int k = 0; k < 5; ++k) {
    const double dt = explicit_dt(c);
    const auto fw = wall_force_on_fluid(c);
    const Vec3 expected = total_momentum(c) + dt * (fw[0] + fw[1] + ext + total_mass(c) * Vec3(0, 0, 50.0));
    step(c, dt);
    const Vec3 p = total_momentum(c);
    EXPECT_LT((p - expected).norm(), 1e-12 * (fw[0].norm() + fw[1].norm()) * dt + 1e-13 * p.norm()) << "step " << k;
  }
}

TEST(SphConservation, MassDensityAndWallsUnderDisturbedShear) {
  FluidCell c = disturbed(100.0, 0.0, 3);
  const double m0 = total_mass(c);
  const std::size_t n0 = c.fluid.size();
  double worst = 0;
  const double dt = explicit_dt(c);
  while (c.time < 0.1 * k_t_visc) {
    step(c, dt);  // throws on a wall crossing
    worst = std::max(worst, density_stats(c).max_abs_error);
  }
  RecordProperty("max_density_deviation", std::to_string(worst));
  EXPECT_EQ(c.fluid.size(), n0);
  EXPECT_EQ(total_mass(c), m0);
  EXPECT_LT(worst, 0.01);
  double volume = 0;
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    EXPECT_LT(std::abs(c.fluid.x[a].x()), 0.5 * k_gap) << "particle " << a;
    volume += c.mass / c.fluid.rho[a];
  }
  EXPECT_NEAR(volume / c.box.volume(), 1.0, 0.01);  // sum m/rho fills the cell
}

TEST(SphConservation, NonFiniteVelocityIsReportedWithParticle) {
  FluidCell c = channel(10, 100.0, 0.0);
  c.fluid.v[7].z() = std::nan("");
  try {
    step(c, explicit_dt(c));
    FAIL() << "no NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("particle 7"), std::string::npos) << e.what();
  }
}

TEST(SphParams, ValidationNamesTheKey) {
  FluidParams p;
  p.viscosity = 0.1;
  p.density = 1000;
  p.spacing = 10e-6;
  p.shear_rate = 100;
  const Box box{150e-6, 50e-6, 120e-6};
  EXPECT_NO_THROW(p.validate(box));
  auto key_of = [&](FluidParams q, Box b) {
    try {
      q.validate(b);
    } catch (const InputError& e) {
      return e.key();
    }
    return std::string("none");
  };
  FluidParams q = p;
  q.viscosity = -1;
  EXPECT_EQ(key_of(q, box), "fluid.viscosity");
  q = p;
  q.density = 0;
  EXPECT_EQ(key_of(q, box), "fluid.density");
  EXPECT_EQ(key_of(p, Box{155e-6, 50e-6, 120e-6}), "fluid.sph_spacing");  // gap not a multiple
  EXPECT_EQ(key_of(p, Box{150e-6, 20e-6, 120e-6}), "fluid.sph_spacing");  // ly < 2h
  q = p;
  q.shear_rate = 0;
  EXPECT_THROW(build_fluid_cell(box, q), InputError);  // no scale for c0
}

// Every key the validation names is one a scene can set (the scene parser
// knows it), or the message says it is an internal parameter: no error sends
// the user looking for a key such as fluid.h_over_dx that does not exist.
TEST(SphParams, ValidationNamesOnlyKeysAUserCanSet) {
  FluidParams p;
  p.viscosity = 0.1;
  p.density = 1000;
  p.spacing = 10e-6;
  p.shear_rate = 100;
  const Box box{150e-6, 50e-6, 120e-6};
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<FluidParams, Box>> cases;
  auto with = [&](auto field, double v) {
    FluidParams q = p;
    q.*field = v;
    cases.push_back({q, box});
  };
  with(&FluidParams::viscosity, -1);
  with(&FluidParams::density, 0);
  with(&FluidParams::spacing, 0);
  with(&FluidParams::h_over_dx, 3);
  with(&FluidParams::sound_speed, -1);
  with(&FluidParams::shear_rate, inf);
  with(&FluidParams::body_force, inf);
  with(&FluidParams::density_tolerance, 0.5);
  with(&FluidParams::cg_tolerance, 0.1);
  cases.push_back({p, Box{0, 50e-6, 120e-6}});
  cases.push_back({p, Box{155e-6, 50e-6, 120e-6}});
  cases.push_back({p, Box{150e-6, 20e-6, 120e-6}});
  const std::string scene = MRF_SOURCE_DIR "/experiments/scenes/couette_sph.toml";
  for (const auto& [q, b] : cases) {
    std::string key, msg;
    try {
      q.validate(b);
      ADD_FAILURE() << "no InputError";
      continue;
    } catch (const InputError& e) {
      key = e.key();
      msg = e.what();
    }
    std::string as_override;  // what the scene parser says about the key
    try {
      load_scene(scene, {key + "=1"});
    } catch (const InputError& e) {
      as_override = e.what();
    }
    const bool scene_key = as_override.find("unknown key") == std::string::npos;
    EXPECT_TRUE(scene_key || msg.find("not a scene key") != std::string::npos)
        << "'" << key << "' is no scene key (" << as_override << ") and the message does not say so: " << msg;
  }
}

TEST(SphParams, AutomaticSoundSpeedFollowsMorris) {
  // Couette, viscous scale binding: c0^2 = nu gdot / delta.
  EXPECT_DOUBLE_EQ(morris_sound_speed(1.0, 1.0, 0.0, 0.0, 0.01), 10.0);
  const FluidCell c = channel(15, 100.0, 0.0);
  EXPECT_NEAR(c.c0, std::sqrt(k_nu * 100.0 / 0.01), 1e-12);
}

TEST(SphParams, LimitsAreNamedAndDtAboveThemRefused) {
  const FluidCell c = channel(15, 100.0, 20.0);
  const auto lim = stability_limits(c, SphImplicit::none);
  ASSERT_EQ(lim.size(), 3u);
  EXPECT_EQ(binding(lim).name.rfind("viscous", 0), 0u);
  EXPECT_NEAR(binding(lim).dt, 0.125 * c.h * c.h / k_nu, 1e-20);
  EXPECT_EQ(stability_limits(c, SphImplicit::viscosity).size(), 2u);  // no viscous limit when implicit
  try {
    check_time_step(c, 1.01 * binding(lim).dt, SphImplicit::none);
    FAIL() << "dt above the viscous limit accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "numerics.dt");
    EXPECT_NE(std::string(e.what()).find("viscous"), std::string::npos);
  }
}

}  // namespace
}  // namespace mrf::test
