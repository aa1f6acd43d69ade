// The implicit integrator in a whole run of the small scene
// (experiments/scenes/small_dem_stokes.toml): the automatic choice prefers it
// at the real modulus of iron and not at a soft one, the run writes its step
// and iteration counts and time-series rows by strain interval, its steps are
// error-controlled (bounded by the wall motion the contact search allows, far
// above the explicit contact limits), and its steady stress equals the explicit one within the error
// bars at a modulus where the explicit scheme is affordable (about 5 s).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

LoadedScene small(const std::vector<std::string>& sets) {
  std::vector<std::string> all{"numerics.threads=1"};
  all.insert(all.end(), sets.begin(), sets.end());
  return load_scene(MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml", all);
}

// At the real modulus the implicit bound is hundreds of explicit steps;
// with the soft modulus at Mn 0.1 the particle Stokes number (0.03) is above
// the inertialess bound, so auto keeps the inertia whatever the step ratio.
TEST(ImplicitChoice, AutoPrefersImplicitAtTheRealModulusAndExplicitAtASoftOne) {
  struct Case {
    const char* youngs;
    const char* mason;
    IntegratorId want;
  };
  for (const auto& [youngs, mason, want] : {Case{"\"200 GPa\"", "0.01", IntegratorId::implicit},
                                            Case{"\"0.2 GPa\"", "0.1", IntegratorId::verlet_exp}}) {
    const LoadedScene s = small({std::string("contact.youngs_modulus=") + youngs, std::string("drive.mason=") + mason});
    const DemParams p = dem_params(s.config);
    const TimeStepChoice t = choose_time_step(s, p);
    EXPECT_EQ(t.scheme, want) << youngs;
    const double explicit_dt = std::max(smallest(dem_limits(p, s.config.gap, IntegratorId::verlet_exp)),
                                        smallest(dem_limits(p, s.config.gap, IntegratorId::overdamped)));
    const auto im = dem_limits(p, s.config.gap, IntegratorId::implicit);
    std::printf("%s: explicit limit %.3e s, implicit bound %.3e s ('%s'), ratio %.1f\n", youngs, explicit_dt,
                smallest(im), binding(im).name.c_str(), smallest(im) / explicit_dt);
    if (want == IntegratorId::implicit) {
      EXPECT_GT(smallest(im), k_implicit_preference * explicit_dt);
      EXPECT_LE(stokes_number(p), k_inertialess_max_stokes);
    } else {
      EXPECT_GT(stokes_number(p), k_inertialess_max_stokes);
    }
    EXPECT_TRUE(std::isinf(im.front().dt)) << "no contact limit for the implicit scheme";
    EXPECT_NE(binding(im).name, "hertz contact");
  }
}

TEST(ImplicitRun, ShortRunReportsCountsAndBoundedSteps) {
  const LoadedScene s = small({"drive.strain=0.6", "drive.warmup_strain=0.1", "numerics.integrator=implicit"});
  const RunSummary r = run_scene(s, RunOptions{"", true});
  const DemParams p = dem_params(s.config);
  const double explicit_dt = smallest(dem_limits(p, s.config.gap, IntegratorId::verlet_exp));
  for (const char* key : {"implicit_rejected_steps", "implicit_newton_iterations", "implicit_linear_iterations",
                          "implicit_newton_failures", "implicit_dt_min", "implicit_dt_max", "implicit_dt_mean"})
    ASSERT_TRUE(r.extra.count(key)) << key;
  std::printf("%ld steps, mean dt %.3e s (%.1f x the verlet_exp limit), %g rejected, %g Newton, %g CG, %.2f s\n",
              r.steps, r.extra.at("implicit_dt_mean"), r.extra.at("implicit_dt_mean") / explicit_dt,
              r.extra.at("implicit_rejected_steps"), r.extra.at("implicit_newton_iterations"),
              r.extra.at("implicit_linear_iterations"), r.wall_seconds);
  EXPECT_EQ(r.integrator, "implicit");
  EXPECT_NEAR(r.extra.at("implicit_dt_mean") * static_cast<double>(r.steps) * r.shear_rate, 0.6, 1e-9);
  EXPECT_LE(r.extra.at("implicit_dt_max"), r.dt * (1 + 1e-12));  // the bound holds
  EXPECT_GT(r.extra.at("implicit_dt_mean"), 5 * explicit_dt);
  EXPECT_GE(r.extra.at("implicit_newton_iterations"), static_cast<double>(r.steps));
  EXPECT_TRUE(std::isfinite(r.stress_total.mean));
  // Inertialess contacts: the overlap follows the load, below the design overlap.
  EXPECT_LT(r.max_overlap_over_radius * p.radius, hertz_overlap_under_load(p.expected_load, p.hertz_k));
}

// numerics.newton_tol reaches the contact Newton solves: a tighter stopping
// residual takes more Newton iterations per step (reports/study/newton_tol.md
// measures the stress it moves: none beyond its error), for model 1 and the
// inertialess coupled scheme.
TEST(ImplicitRun, NewtonToleranceReachesTheSolves) {
  for (const char* model : {"scene.model=dem_stokes", "scene.model=demsph_dd"}) {
    double per_step[2];
    int k = 0;
    for (const char* tol : {"numerics.newton_tol=1e-4", "numerics.newton_tol=1e-8"}) {
      const RunSummary r = run_scene(small({model, tol, "drive.strain=0.6", "drive.warmup_strain=0.1",
                                            "drive.vary='magnetization'", "drive.shear_rate=1e3",
                                            "contact.youngs_modulus='200 GPa'", "drive.mason=0.01"}),
                                     RunOptions{"", true});
      ASSERT_NE(r.integrator.find("implicit"), std::string::npos) << model << " " << r.integrator;
      per_step[k++] = r.extra.at("implicit_newton_iterations") / static_cast<double>(r.steps);
    }
    std::printf("%s: Newton iterations per step %.2f (1e-4 R) against %.2f (1e-8 R)\n", model, per_step[0],
                per_step[1]);
    EXPECT_LT(per_step[0] + 1.0, per_step[1]) << model;
  }
}

// A short run: the error-controlled step is bounded by the averaging
// window (at least 64 steps in it), so the run writes its rows instead of
// being refused; with output.every set too large, that key and its line are
// named.
TEST(ImplicitRun, ShortRunTakesAtLeast64StepsInItsWindow) {
  const RunSummary r = run_scene(small({"drive.strain=0.3", "drive.warmup_strain=0.1", "numerics.integrator=implicit"}),
                                 RunOptions{"", true});
  EXPECT_EQ(r.binding_limit, "averaging window");
  EXPECT_NEAR(r.dt * r.shear_rate, 0.2 / 64, 1e-12);
  EXPECT_GE(r.steps, 96);  // 0.3 / (0.2 / 64)
  EXPECT_TRUE(std::isfinite(r.stress_total.mean));
  // The Verlet skin was chosen for cost (within 0.05 R and the minimum
  // image's bound, 0.4 R here); a given skin is kept.
  const double skin = r.extra.at("neighbor_skin_over_radius");
  EXPECT_GE(skin, 0.05);
  EXPECT_LE(skin, 0.4 + 1e-12);
  EXPECT_GT(r.extra.at("steps_per_pair_list_build"), 1.0);
  const RunSummary g = run_scene(
      small({"drive.strain=0.3", "drive.warmup_strain=0.1", "numerics.integrator=implicit", "numerics.skin=\"0.3 um\""}),
      RunOptions{"", true});
  EXPECT_DOUBLE_EQ(g.extra.at("neighbor_skin_over_radius"), 0.3 / 2.5);
  try {
    run_scene(small({"drive.strain=0.3", "drive.warmup_strain=0.1", "numerics.integrator=implicit", "output.every=4"}),
              RunOptions{"", true});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "output.every") << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("--set output.every=4: ", 0), 0u) << e.what();
  }
}

// Y = 2 GPa (explicit verlet_exp at dt = 1.8e-8 s), strain 5, averaged from
// 1.5; about 5 s, so it runs with the fast label.
TEST(ImplicitRunAgreement, SteadyStressEqualsExplicitWithinErrorBars) {
  const std::vector<std::string> base{"contact.youngs_modulus=\"2 GPa\"", "drive.strain=5", "drive.warmup_strain=1.5"};
  std::vector<std::string> ex = base, im = base;
  ex.push_back("numerics.integrator=verlet_exp");
  im.push_back("numerics.integrator=implicit");
  const RunSummary a = run_scene(small(ex), RunOptions{"", true});
  const RunSummary b = run_scene(small(im), RunOptions{"", true});
  const double bar = std::hypot(a.stress_total.err, b.stress_total.err);
  std::printf("explicit %.1f +- %.1f Pa (%.2f s), implicit %.1f +- %.1f Pa (%.2f s), difference %.1f Pa = %.2f sigma\n",
              a.stress_total.mean, a.stress_total.err, a.wall_seconds, b.stress_total.mean, b.stress_total.err,
              b.wall_seconds, b.stress_total.mean - a.stress_total.mean,
              std::abs(b.stress_total.mean - a.stress_total.mean) / bar);
  EXPECT_LT(std::abs(b.stress_total.mean - a.stress_total.mean), 2 * bar);
  EXPECT_LT(bar, 0.06 * a.stress_total.mean) << "error bars too wide for the comparison to mean anything";
}

}  // namespace
}  // namespace mrf
