#include "mrf/quasistatic/fire.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"

namespace mrf {

namespace {

void require(bool ok, const std::string& key, double value, const char* why) {
  if (!ok) throw InputError(key, format_short(value), "", why);
}

void check_finite(const std::vector<Vec3>& f, long iteration) {
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!f[i].allFinite())
      throw NumericalError("FIRE: non-finite force on particle " + std::to_string(i) + " at iteration " +
                           std::to_string(iteration));
}

}  // namespace

void FireOptions::validate(const std::string& p) const {
  require(force_tol > 0, p + "force_tol", force_tol, "must be > 0 (N)");
  require(max_iterations > 0, p + "max_iterations", static_cast<double>(max_iterations), "must be > 0");
  require(dt_max > 0, p + "dt_max", dt_max, "must be > 0 (s)");
  require(dt_start > 0 && dt_start <= dt_max, p + "dt_start", dt_start, "must be in (0, dt_max]");
  require(dt_min > 0 && dt_min <= dt_start, p + "dt_min", dt_min, "must be in (0, dt_start]");
  require(max_step > 0, p + "max_step", max_step, "must be > 0 (m)");
  require(mass > 0, p + "mass", mass, "must be > 0 (kg)");
  require(n_delay >= 0, p + "n_delay", n_delay, "must be >= 0");
  require(f_inc > 1, p + "f_inc", f_inc, "must be > 1");
  require(f_dec > 0 && f_dec < 1, p + "f_dec", f_dec, "must be in (0, 1)");
  require(alpha_start > 0 && alpha_start < 1, p + "alpha_start", alpha_start, "must be in (0, 1)");
  require(f_alpha > 0 && f_alpha <= 1, p + "f_alpha", f_alpha, "must be in (0, 1]");
  require(max_uphill > 0, p + "max_uphill", static_cast<double>(max_uphill), "must be > 0");
}

double max_force_norm(const std::vector<Vec3>& f) {
  double m2 = 0;
  for (const Vec3& g : f) m2 = std::max(m2, g.squaredNorm());
  return std::sqrt(m2);
}

FireResult fire_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const FireOptions& o, const FireForce& force) {
  const std::size_t n = x.size();
  FireResult r;
  r.energy = force();
  check_finite(f, 0);
  r.max_force = max_force_norm(f);
  if (r.max_force < o.force_tol) {
    r.converged = true;
    r.stop_reason = "converged";
    return r;
  }
  std::vector<Vec3> v(n, Vec3::Zero());
  const double inv_mass = 1.0 / o.mass;
  double dt = o.dt_start, alpha = o.alpha_start;
  long downhill = 0, uphill = 0;
  for (long it = 1; it <= o.max_iterations; ++it) {
    double power = 0;
    for (std::size_t i = 0; i < n; ++i) power += f[i].dot(v[i]);
    if (power > 0) {
      uphill = 0;
      if (++downhill > o.n_delay) {
        dt = std::min(dt * o.f_inc, o.dt_max);
        alpha *= o.f_alpha;
      }
    } else {
      downhill = 0;
      if (++uphill > o.max_uphill) {
        r.stop_reason = "uphill";
        return r;
      }
      // initial delay: no cut of dt during the first n_delay steps
      if (it > o.n_delay) {
        if (dt * o.f_dec >= o.dt_min) dt *= o.f_dec;
        alpha = o.alpha_start;
      }
      for (std::size_t i = 0; i < n; ++i) {
        x[i] -= 0.5 * dt * v[i];
        v[i].setZero();
      }
    }
    // semi-implicit Euler with the FIRE mixing v <- (1 - alpha) v + alpha |v| F^
    double v2 = 0, f2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      v[i] += dt * inv_mass * f[i];
      v2 += v[i].squaredNorm();
      f2 += f[i].squaredNorm();
    }
    const double mix = f2 > 0 ? alpha * std::sqrt(v2 / f2) : 0.0;
    double vmax2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      v[i] = (1.0 - alpha) * v[i] + mix * f[i];
      vmax2 = std::max(vmax2, v[i].squaredNorm());
    }
    // Cap the largest displacement (as LAMMPS's dmax): the step itself is
    // shortened, so the next steps start from the shorter one.
    const double vmax = std::sqrt(vmax2);
    if (dt * vmax > o.max_step) dt = o.max_step / vmax;
    for (std::size_t i = 0; i < n; ++i) x[i] += dt * v[i];
    r.energy = force();
    check_finite(f, it);
    r.iterations = it;
    r.max_force = max_force_norm(f);
    if (r.max_force < o.force_tol) {
      r.converged = true;
      r.stop_reason = "converged";
      return r;
    }
  }
  r.stop_reason = "max_iterations";
  return r;
}

}  // namespace mrf
