#include "mrf/quasistatic/descent.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"

namespace mrf {

void DescentOptions::validate(const std::string& p) const {
  const auto require = [&](bool ok, const char* name, double v, const char* why) {
    if (!ok) throw InputError(p + name, format_short(v), "", why);
  };
  require(force_tol > 0, "force_tol", force_tol, "must be > 0 (N)");
  require(max_evaluations > 0, "max_evaluations", static_cast<double>(max_evaluations), "must be > 0");
  require(step > 0, "step", step, "must be > 0 (m/N)");
  require(max_step > 0, "max_step", max_step, "must be > 0 (m)");
}

DescentResult descent_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const DescentOptions& o,
                               const FireForce& force) {
  DescentResult r;
  for (;;) {
    r.energy = force();
    ++r.evaluations;
    for (std::size_t i = 0; i < f.size(); ++i)
      if (!f[i].allFinite())
        throw NumericalError("steepest descent: non-finite force on particle " + std::to_string(i) + " at evaluation " +
                             std::to_string(r.evaluations));
    r.max_force = max_force_norm(f);
    if (r.max_force < o.force_tol) {
      r.converged = true;
      r.stop_reason = "converged";
      return r;
    }
    if (r.evaluations >= o.max_evaluations) {
      r.stop_reason = "max_evaluations";
      return r;
    }
    // One Euler step of the gradient flow; the cap only bites far from a
    // minimum (overlapping spheres of a packing), where it keeps the path.
    const double h = std::min(o.step, o.max_step / r.max_force);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += h * f[i];
  }
}

}  // namespace mrf
