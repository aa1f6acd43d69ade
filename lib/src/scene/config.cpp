#include "mrf/scene/config.hpp"

#include <omp.h>

#include <cmath>
#include <sstream>

#include "mrf/vec.hpp"

namespace mrf {

void use_scene_threads(const SceneConfig& c) {
  if (c.threads > 0) omp_set_num_threads(c.threads);
}

const char* to_string(ModelId m) {
  switch (m) {
    case ModelId::dem_stokes: return "dem_stokes";
    case ModelId::demsph_stokes: return "demsph_stokes";
    case ModelId::demsph_dd: return "demsph_dd";
    case ModelId::dem_dd: return "dem_dd";
  }
  return "?";
}

const char* to_string(IntegratorId i) {
  switch (i) {
    case IntegratorId::automatic: return "auto";
    case IntegratorId::verlet_exp: return "verlet_exp";
    case IntegratorId::overdamped: return "overdamped";
    case IntegratorId::implicit: return "implicit";
  }
  return "?";
}

double mason_from_shear_rate(double shear_rate, double viscosity, double magnetization) {
  return 9.0 * viscosity * shear_rate / (2.0 * k_mu0 * magnetization * magnetization);
}

double shear_rate_from_mason(double mason, double viscosity, double magnetization) {
  return mason * 2.0 * k_mu0 * magnetization * magnetization / (9.0 * viscosity);
}

double magnetization_from_mason(double mason, double viscosity, double shear_rate) {
  return std::sqrt(9.0 * viscosity * shear_rate / (2.0 * k_mu0 * mason));
}

const char* to_string(MasonBy v) { return v == MasonBy::shear_rate ? "shear_rate" : "magnetization"; }
const char* to_string(EosReference v) { return v == EosReference::start ? "start" : "common"; }

std::optional<DriveProblem> derived_drive_problem(const SceneConfig& c, bool mason_given) {
  const auto fail = [&](const char* key, const char* what, double value) {
    std::ostringstream why;
    why << "gives " << what << " = " << value << " with fluid.viscosity = " << c.viscosity
        << " Pa s (Mn = 9 eta gdot / (2 mu0 M^2)): outside what a run can use";
    return DriveProblem{key, why.str()};
  };
  const auto usable = [](double v) { return std::isfinite(v) && v > 0; };
  if (c.vary == MasonBy::magnetization) {
    if (!usable(c.magnetization)) return fail("drive.mason", "magnetization (A/m)", c.magnetization);
  } else if (mason_given) {
    if (!usable(c.shear_rate)) return fail("drive.mason", "shear rate (1/s)", c.shear_rate);
  } else if (c.magnetization > 0 && !usable(c.mason)) {
    return fail("drive.shear_rate", "Mason number", c.mason);
  }
  return std::nullopt;
}

}  // namespace mrf
