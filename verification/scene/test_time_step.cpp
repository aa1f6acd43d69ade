// The time step of the run driver (scene/build_model): the automatic choice
// from the stability limits and the refusal of a user dt above them, naming
// key, value, line and limit (DESIGN.md §Numerics), and the rule by which
// `auto` picks the integrator (the Stokes bound, then the largest limit).
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run.hpp"
#include "support/small_scene.hpp"

namespace mrf {
namespace {

using namespace mrf::test;

// ---- the time step -------------------------------------------------------

struct Limit {
  double dt;
  std::string name;
};

Limit binding_limit(const LoadedScene& s) {
  const TimeStepChoice t = choose_time_step(s, dem_params(s.config));
  return {binding(t.limits).dt, binding(t.limits).name};
}

std::string input_error(const LoadedScene& s) {
  try {
    choose_time_step(s, dem_params(s.config));
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "numerics.dt");
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

// The value in "... key 'numerics.dt' = VALUE: ..." read back in seconds: a
// plain number (SI) or "<number> <unit>", quoted or not.
std::optional<double> shown_dt(const std::string& message) {
  const std::string tag = "key 'numerics.dt' = ";
  std::size_t b = message.find(tag);
  if (b == std::string::npos) return std::nullopt;
  b += tag.size();
  std::string v = message.substr(b, message.find(": ", b) - b);
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end != v.c_str() && trim(end).empty()) return x;
  try {
    return parse_quantity(v, Dim::time);
  } catch (const ValueError&) {
    return std::nullopt;
  }
}

TEST(RunTimeStep, AutomaticDtIsTheSafetyFractionOfTheBindingLimit) {
  const LoadedScene s = scene();
  const TimeStepChoice t = choose_time_step(s, dem_params(s.config));
  EXPECT_EQ(t.scheme, IntegratorId::verlet_exp);
  EXPECT_DOUBLE_EQ(t.dt, s.config.dt_safety * binding(t.limits).dt);
  EXPECT_EQ(s.config.dt_safety, 0.5);
}

TEST(RunTimeStep, DtAboveTheLimitInTheFileNamesKeyValueLineAndLimit) {
  const Limit lim = binding_limit(scene());
  ASSERT_EQ(lim.name, "hertz contact");
  for (const double factor : {2.0, 1.01}) {
    const double dt = factor * lim.dt;
    const std::string text = with_dt(g17(dt));
    const std::string where = k_source + ":" + std::to_string(line_of(text, "dt = "));
    const LoadedScene s = scene({}, text);
    const std::string msg = input_error(s);
    EXPECT_NE(msg.find("numerics.dt"), std::string::npos) << msg;
    EXPECT_NE(msg.find(where), std::string::npos) << "expected " << where << " in: " << msg;
    EXPECT_NE(msg.find("'" + lim.name + "'"), std::string::npos) << msg;
    const std::optional<double> shown = shown_dt(msg);
    ASSERT_TRUE(shown.has_value()) << msg;
    EXPECT_LT(std::abs(*shown - dt), 1e-5 * dt)
        << "the message shows numerics.dt as " << *shown << " s, the file says " << dt
        << " s: " << msg;
    // run_scene refuses it too, before any work.
    EXPECT_THROW(run_scene(s, RunOptions{"", true}), InputError);
  }
  // The same with units.
  const std::string ns = g17(2e9 * lim.dt) + " ns";
  const std::string msg = input_error(scene({}, with_dt("\"" + ns + "\"")));
  const std::optional<double> shown = shown_dt(msg);
  ASSERT_TRUE(shown.has_value()) << msg;
  EXPECT_LT(std::abs(*shown - 2 * lim.dt), 1e-5 * lim.dt) << msg;
}

TEST(RunTimeStep, DtAboveTheLimitFromAnOverrideNamesTheOverride) {
  const Limit lim = binding_limit(scene());
  const std::string value = g17(2 * lim.dt);
  const std::string msg = input_error(scene({"numerics.dt=" + value}));
  EXPECT_NE(msg.find("--set numerics.dt=" + value), std::string::npos) << msg;
  EXPECT_NE(msg.find("'" + lim.name + "'"), std::string::npos) << msg;
  EXPECT_EQ(msg.find(k_source + ":"), std::string::npos) << "an override has no file line: " << msg;
  const std::optional<double> shown = shown_dt(msg);
  ASSERT_TRUE(shown.has_value()) << msg;
  EXPECT_LT(std::abs(*shown - 2 * lim.dt), 1e-5 * lim.dt) << msg;
}

TEST(RunTimeStep, DtJustBelowTheLimitPassesValidation) {
  const Limit lim = binding_limit(scene());
  for (const double factor : {0.99, 1.0}) {
    const LoadedScene s = scene({"numerics.dt=" + g17(factor * lim.dt)});
    TimeStepChoice t;
    ASSERT_NO_THROW(t = choose_time_step(s, dem_params(s.config))) << factor;
    EXPECT_EQ(t.dt, *s.config.dt);
    EXPECT_EQ(t.scheme, IntegratorId::verlet_exp);
  }
}

// A dt that validation accepts should also run: the contact limit the run
// enforces (DemModel::overlap_limit) should not stop it in the first steps.
TEST(RunTimeStep, DtJustBelowTheLimitRunsToTheEnd) {
  const Limit lim = binding_limit(scene());
  const LoadedScene s = scene({"numerics.dt=" + g17(0.99 * lim.dt)});
  try {
    const RunSummary r = run_scene(s, RunOptions{"", true});
    EXPECT_GE(r.strain, k_strain);
  } catch (const NumericalError& e) {
    ADD_FAILURE() << "numerics.dt = 0.99 x the '" << lim.name << "' limit (" << 0.99 * lim.dt
                  << " s) passed validation, but the run stopped: " << e.what();
  }
}

// ---- the integrator choice -------------------------------------------------

// Auto keeps the particles' inertia (verlet_exp) above the Stokes bound;
// below it, it picks the explicit scheme whose binding (smallest) limit is
// largest, ties to verlet_exp, with dt = dt_safety times that limit; unless
// that limit is more than k_implicit_preference times below the implicit
// step bound: then implicit, with dt = the bound (its largest step).
void expect_auto_rule(const LoadedScene& s, const std::string& label) {
  const DemParams p = dem_params(s.config);
  const auto ve = dem_limits(p, s.config.gap, IntegratorId::verlet_exp);
  const auto od = dem_limits(p, s.config.gap, IntegratorId::overdamped);
  const auto im = dem_limits(p, s.config.gap, IntegratorId::implicit);
  const double explicit_dt = std::max(smallest(ve), smallest(od));
  const IntegratorId want = stokes_number(p) > k_inertialess_max_stokes          ? IntegratorId::verlet_exp
                            : k_implicit_preference * explicit_dt < smallest(im) ? IntegratorId::implicit
                            : smallest(ve) >= smallest(od)                       ? IntegratorId::verlet_exp
                                                                                 : IntegratorId::overdamped;
  const TimeStepChoice t = choose_time_step(s, p);
  EXPECT_EQ(t.scheme, want) << label << ": verlet_exp limit " << smallest(ve)
                            << " s, overdamped limit " << smallest(od) << " s, implicit bound " << smallest(im);
  // The implicit run also keeps 64 steps in its averaging window.
  auto im_run = im;
  im_run.push_back(window_limit(s.config));
  EXPECT_EQ(t.dt, want == IntegratorId::implicit ? smallest(im_run) : s.config.dt_safety * explicit_dt) << label;
  const auto& limits = want == IntegratorId::implicit ? im_run : want == IntegratorId::verlet_exp ? ve : od;
  EXPECT_EQ(binding(t.limits).name, binding(limits).name) << label;
}

TEST(RunIntegratorChoice, AutoPicksTheSchemeWhoseBindingLimitIsLargest) {
  for (const char* density : {"7800", "78", "7.8", "0.078"})
    for (const char* youngs : {"\"200 GPa\"", "\"2 GPa\""}) {
      const std::vector<std::string> set = {std::string("particles.density=") + density,
                                            std::string("contact.youngs_modulus=") + youngs,
                                            "numerics.integrator=auto"};
      expect_auto_rule(scene(set), set[0] + " " + set[1]);
    }
}

// Above the Stokes bound the particles keep their inertia even where the
// implicit scheme's step bound is many times the explicit one (iron's
// modulus), which would otherwise choose it.
TEST(RunIntegratorChoice, AutoKeepsInertiaAboveTheStokesBound) {
  for (const char* mason : {"0.003", "0.01"}) {
    const LoadedScene s = scene({"particles.density=78000", std::string("drive.mason=") + mason,
                                 "contact.youngs_modulus=\"200 GPa\"", "numerics.integrator=auto"});
    const DemParams p = dem_params(s.config);
    ASSERT_GT(stokes_number(p), k_inertialess_max_stokes) << mason;
    EXPECT_GT(smallest(dem_limits(p, s.config.gap, IntegratorId::implicit)),
              k_implicit_preference * smallest(dem_limits(p, s.config.gap, IntegratorId::verlet_exp)));
    EXPECT_EQ(choose_time_step(s, p).scheme, IntegratorId::verlet_exp) << mason;
  }
}

TEST(RunIntegratorChoice, TinyDensityRunReportsTheSchemeOfTheRule) {
  const std::vector<std::string> set = {"particles.density=7.8", "contact.youngs_modulus=\"0.45 GPa\"",
                                        "numerics.integrator=auto", "drive.mason=0.1",
                                        "drive.strain=0.5", "drive.warmup_strain=0.1",
                                        "output.every=0"};
  const LoadedScene s = scene(set);
  const DemParams p = dem_params(s.config);
  const auto ve = dem_limits(p, s.config.gap, IntegratorId::verlet_exp);
  const auto od = dem_limits(p, s.config.gap, IntegratorId::overdamped);
  expect_auto_rule(s, "tiny density");
  const TimeStepChoice t = choose_time_step(s, p);
  const RunSummary r = run_scene(s, RunOptions{"", true});
  EXPECT_EQ(r.integrator, to_string(t.scheme));
  EXPECT_EQ(r.binding_limit, binding(t.limits).name);
  if (t.scheme != IntegratorId::implicit) {
    EXPECT_EQ(r.binding_limit, "hertz contact");
  }
  // St << 1 here: the two contact limits nearly coincide (the exponential
  // integrator tends to explicit overdamped Euler as tau_p -> 0).
  EXPECT_LT(r.stokes_number, 1e-4);
  EXPECT_LT(rel(smallest(ve), smallest(od)), 1e-3);
  RecordProperty("verlet_exp_limit_s", g17(smallest(ve)));
  RecordProperty("overdamped_limit_s", g17(smallest(od)));
}

}  // namespace
}  // namespace mrf
