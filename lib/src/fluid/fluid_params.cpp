#include "mrf/fluid/fluid_params.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mrf/error.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/io/quantity.hpp"

namespace mrf {

namespace {

void require_positive(const char* key, double v) {
  if (!(v > 0) || !std::isfinite(v)) throw InputError(key, format_short(v), "", "must be positive and finite");
}

// A parameter no scene sets (the solver's own setting, or a test's): the
// error says so instead of naming a scene key the user cannot find.
[[noreturn]] void internal_error(const char* name, double v, const std::string& why) {
  throw InputError(std::string("FluidParams::") + name, format_short(v), "",
                   why + " (an internal parameter of the SPH solver, not a scene key: the code that built the "
                         "fluid set it)");
}

// True when length / dx is a whole number to 1e-6 relative.
bool is_multiple(double length, double dx) {
  const double n = length / dx;
  return std::abs(n - std::round(n)) < 1e-6 * std::max(1.0, n);
}

}  // namespace

void FluidParams::validate(const Box& box) const {
  require_positive("fluid.viscosity", viscosity);
  require_positive("fluid.density", density);
  require_positive("fluid.sph_spacing", spacing);
  if (!(h_over_dx >= 1.0 && h_over_dx <= 2.5))
    internal_error("h_over_dx", h_over_dx, "smoothing length / sph_spacing must lie in [1, 2.5]");
  if (!(sound_speed >= 0) || !std::isfinite(sound_speed))
    throw InputError("fluid.sound_speed", format_short(sound_speed), "", "must be >= 0 (0 = automatic)");
  if (!std::isfinite(shear_rate))
    throw InputError("drive.shear_rate", format_short(shear_rate), "", "must be finite (given, or derived from drive.mason)");
  if (!std::isfinite(body_force)) internal_error("body_force", body_force, "body force along z must be finite");
  if (!(density_tolerance > 0 && density_tolerance < 0.1))
    internal_error("density_tolerance", density_tolerance,
                   "target density variation of the automatic sound speed must lie in (0, 0.1)");
  if (!(cg_tolerance > 0 && cg_tolerance < 1e-3))
    internal_error("cg_tolerance", cg_tolerance, "residual of the implicit viscous solve must lie in (0, 1e-3)");
  const struct {
    const char* key;
    double length;
  } sides[] = {{"box.gap", box.gap}, {"box.ly", box.ly}, {"box.lz", box.lz}};
  for (const auto& s : sides) {
    require_positive(s.key, s.length);
    if (!is_multiple(s.length, spacing))
      throw InputError("fluid.sph_spacing", format_short(spacing), "",
                       std::string("must divide ") + s.key + " = " + format_short(s.length) + " a whole number of times");
  }
  const double support = k_kernel_support * h();
  if (box.ly <= support || box.lz <= support)
    throw InputError("fluid.sph_spacing", format_short(spacing), "",
                     "kernel support 2h = " + format_short(support) + " m must be shorter than box.ly and box.lz");
}

double morris_sound_speed(double v0, double l0, double nu, double body_force, double delta) {
  const double c2 = std::max({v0 * v0, nu * v0 / l0, std::abs(body_force) * l0}) / delta;
  return std::sqrt(c2);
}

double sound_speed(const FluidParams& p, const Box& box) {
  if (p.sound_speed > 0) return p.sound_speed;
  const double nu = p.kinematic_viscosity();
  const double l0 = 0.5 * box.gap;
  const double v0 = std::max(std::abs(p.shear_rate) * l0, std::abs(p.body_force) * box.gap * box.gap / (8.0 * nu));
  const double c0 = morris_sound_speed(v0, l0, nu, p.body_force, p.density_tolerance);
  if (!(c0 > 0))
    throw InputError("fluid.sound_speed", "0", "",
                     "cannot be chosen automatically without flow (shear_rate = body_force = 0); give it");
  return c0;
}

}  // namespace mrf
