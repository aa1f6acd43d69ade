#include "mrf/quasistatic/lbfgs.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"

namespace mrf {

namespace {

void require(bool ok, const std::string& key, double value, const char* why) {
  if (!ok) throw InputError(key, format_short(value), "", why);
}

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i].dot(b[i]);
  return s;
}

// The correction pairs s_k = x_{k+1} - x_k, y_k = grad_{k+1} - grad_k, newest
// last, at most `memory` of them (a ring: the oldest storage is reused).
struct History {
  std::vector<std::vector<Vec3>> s, y;
  std::vector<double> rho;  // 1 / (y_k . s_k)
  std::size_t head = 0, size = 0;

  explicit History(std::size_t m) : s(m), y(m), rho(m, 0.0) {}
  std::size_t index(std::size_t k) const { return (head + k) % s.size(); }  // k = 0: oldest
  void clear() { head = size = 0; }
  // Slot for a new pair (the oldest one's when full); push() makes it current.
  std::size_t next_slot() const { return size < s.size() ? index(size) : head; }
  void push(double rho_new) {
    const std::size_t slot = next_slot();
    rho[slot] = rho_new;
    if (size < s.size())
      ++size;
    else
      head = (head + 1) % s.size();
  }
};

// d = H f with the two-loop recursion (N&W Algorithm 7.4), H0 = gamma I.
// The recursion is linear in its input, so starting it from f = -grad E
// gives the search direction -H grad E directly.
void two_loop(const History& h, double gamma, const std::vector<Vec3>& f, std::vector<Vec3>& d,
              std::vector<double>& alpha) {
  d = f;
  alpha.assign(h.size, 0.0);
  for (std::size_t k = h.size; k-- > 0;) {
    const std::size_t j = h.index(k);
    alpha[k] = h.rho[j] * dot(h.s[j], d);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] -= alpha[k] * h.y[j][i];
  }
  for (Vec3& v : d) v *= gamma;
  for (std::size_t k = 0; k < h.size; ++k) {
    const std::size_t j = h.index(k);
    const double beta = h.rho[j] * dot(h.y[j], d);
    for (std::size_t i = 0; i < d.size(); ++i) d[i] += (alpha[k] - beta) * h.s[j][i];
  }
}

}  // namespace

void LbfgsOptions::validate(const std::string& p) const {
  require(force_tol > 0, p + "force_tol", force_tol, "must be > 0 (N)");
  require(max_evaluations > 0, p + "max_evaluations", static_cast<double>(max_evaluations), "must be > 0");
  require(memory >= 1 && memory <= 1000, p + "memory", memory, "must be in [1, 1000]");
  require(max_step > 0, p + "max_step", max_step, "must be > 0 (m)");
  require(initial_scale > 0, p + "initial_scale", initial_scale, "must be > 0 (m/N)");
  require(c1 > 0 && c1 < 0.5, p + "c1", c1, "must be in (0, 0.5)");
  require(c2 > c1 && c2 < 1, p + "c2", c2, "must be in (c1, 1)");
  require(energy_slack >= 0 && energy_slack < 1e-3, p + "energy_slack", energy_slack, "must be in [0, 1e-3)");
  require(max_line_evaluations >= 2, p + "max_line_evaluations", max_line_evaluations, "must be >= 2");
  require(max_failures >= 1, p + "max_failures", max_failures, "must be >= 1");
}

LbfgsResult lbfgs_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const LbfgsOptions& o, const FireForce& force) {
  const std::size_t n = x.size();
  LbfgsResult r;
  enum class Trial { evaluated, converged, budget };
  // The only place x changes: x = x0 + a d, then the forces there. So on
  // any return x is the point of the callback's last evaluation.
  std::vector<Vec3> x0, f0, d;
  std::vector<double> alpha;
  double trial_energy = 0, trial_slope = 0;  // E and phi'(a) = -f.d at the last trial
  const auto evaluate = [&]() {
    r.energy = force();
    ++r.evaluations;
    for (std::size_t i = 0; i < n; ++i)
      if (!f[i].allFinite())
        throw NumericalError("L-BFGS: non-finite force on particle " + std::to_string(i) + " at evaluation " +
                             std::to_string(r.evaluations));
    r.max_force = max_force_norm(f);
    return r.max_force < o.force_tol;
  };
  const auto trial = [&](double a) {
    if (r.evaluations >= o.max_evaluations) return Trial::budget;
    for (std::size_t i = 0; i < n; ++i) x[i] = x0[i] + a * d[i];
    if (evaluate()) return Trial::converged;
    trial_energy = r.energy;
    trial_slope = -dot(f, d);
    return Trial::evaluated;
  };
  const auto finish = [&](bool converged, const char* why) {
    r.converged = converged;
    r.stop_reason = why;
    return r;
  };

  if (evaluate()) return finish(true, "converged");
  History h(static_cast<std::size_t>(o.memory));
  double gamma = o.initial_scale;  // H0 = gamma I; after the first pair, s.y / y.y of the newest pair
  int failures = 0;
  x0 = x;
  f0 = f;
  double e0 = r.energy;
  for (;;) {
    // Search direction; steepest descent when the memory is empty or its
    // direction is not downhill (round-off in a nearly singular H).
    two_loop(h, gamma, f0, d, alpha);
    double slope0 = -dot(f0, d);  // phi'(0)
    if (!(slope0 < 0) && h.size > 0) {
      h.clear();
      ++r.resets;
      two_loop(h, gamma, f0, d, alpha);
      slope0 = -dot(f0, d);
    }
    if (!(slope0 < 0)) return finish(false, "line_search");  // f = 0 on every free component: cannot happen above tol
    double dmax2 = 0;
    for (const Vec3& v : d) dmax2 = std::max(dmax2, v.squaredNorm());
    const double a_max = o.max_step / std::sqrt(dmax2);  // the step cap
    const double slack = o.energy_slack * std::abs(e0);
    const auto armijo = [&](double a, double e) { return e <= e0 + o.c1 * a * slope0 + slack; };
    const auto curvature = [&](double slope) { return std::abs(slope) <= o.c2 * std::abs(slope0); };

    // Line search for the strong Wolfe conditions (N&W Algorithm 3.5), the
    // unit step first (the quasi-Newton step), capped at a_max.
    double a_prev = 0, e_prev = e0, s_prev = slope0;
    double a = std::min(1.0, a_max);
    bool accepted = false;
    double lo = 0, e_lo = e0, s_lo = slope0, hi = 0, e_hi = 0, s_hi = 0;
    bool zoom = false;
    int used = 0;
    while (used < o.max_line_evaluations) {
      const Trial t = trial(a);
      if (t == Trial::converged) return finish(true, "converged");
      if (t == Trial::budget) return finish(false, "max_evaluations");
      ++used;
      const double e = trial_energy, s = trial_slope;
      if (!armijo(a, e) || (a_prev > 0 && e > e_prev + slack)) {
        lo = a_prev, e_lo = e_prev, s_lo = s_prev, hi = a, e_hi = e, s_hi = s;
        zoom = true;
        break;
      }
      if (curvature(s)) {
        accepted = true;
        break;
      }
      if (s >= 0) {
        lo = a, e_lo = e, s_lo = s, hi = a_prev, e_hi = e_prev, s_hi = s_prev;
        zoom = true;
        break;
      }
      // Still steeply downhill: a longer step, unless the cap is reached; a
      // capped downhill step is taken as it is (as FIRE's capped step).
      if (a >= a_max) {
        accepted = true;
        break;
      }
      double next = 4.0 * a;
      if (s > s_prev) next = a - s * (a - a_prev) / (s - s_prev);  // secant on phi' (convex along d)
      a_prev = a, e_prev = e, s_prev = s;
      a = std::min(std::clamp(next, 2.0 * a, 10.0 * a), a_max);
    }
    // Zoom (N&W Algorithm 3.6): lo satisfies the decrease test and has the
    // lowest energy seen, phi'(lo) points toward hi. The trial is the secant
    // root of phi' when phi' changes sign between lo and hi (no energies
    // needed: robust below the energy round-off), else the minimum of the
    // quadratic through phi(lo), phi'(lo), phi(hi) (hi rejected on energy),
    // kept within the inner 80 % of the bracket.
    while (zoom && used < o.max_line_evaluations) {
      const double w = hi - lo;
      double t = 0.5;
      if (s_hi * w > 0 && s_lo * w < 0) {
        t = s_lo / (s_lo - s_hi);
      } else {
        const double curv = e_hi - e_lo - s_lo * w;  // quadratic coefficient times w^2
        if (curv > 0) t = -s_lo * w / (2.0 * curv);
      }
      if (!(t >= 0.1 && t <= 0.9)) t = std::clamp(std::isfinite(t) ? t : 0.5, 0.1, 0.9);
      a = lo + t * w;
      const Trial tr = trial(a);
      if (tr == Trial::converged) return finish(true, "converged");
      if (tr == Trial::budget) return finish(false, "max_evaluations");
      ++used;
      const double e = trial_energy, s = trial_slope;
      if (!armijo(a, e) || e > e_lo + slack) {
        hi = a, e_hi = e, s_hi = s;
      } else {
        if (curvature(s)) {
          accepted = true;
          break;
        }
        if (s * (hi - lo) >= 0) hi = lo, e_hi = e_lo, s_hi = s_lo;
        lo = a, e_lo = e, s_lo = s;
      }
      if (std::abs(hi - lo) <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) break;
    }

    if (accepted) {
      failures = 0;
      ++r.iterations;
      // s = a d, y = grad(x) - grad(x0) = f0 - f; stored only when s.y > 0
      // (the curvature pair keeps H positive definite). Tested before it is
      // written: with a full memory the slot is the oldest pair's.
      double sy = 0, yy = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 yi = f0[i] - f[i];
        sy += a * d[i].dot(yi);
        yy += yi.squaredNorm();
      }
      if (sy > 0 && yy > 0) {
        const std::size_t slot = h.next_slot();
        std::vector<Vec3>& sv = h.s[slot];
        std::vector<Vec3>& yv = h.y[slot];
        sv.resize(n);
        yv.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
          sv[i] = a * d[i];
          yv[i] = f0[i] - f[i];
        }
        h.push(1.0 / sy);
        gamma = sy / yy;
      }
      x0 = x;
      f0 = f;
      e0 = r.energy;
      continue;
    }
    // Failed line search: forget the curvature pairs and go on from the
    // best point seen (lo, where the decrease test held), or x0 itself;
    // the forces there are evaluated again so that the callback's last
    // evaluation is the current point.
    ++r.resets;
    h.clear();
    if (++failures > o.max_failures) return finish(false, "line_search");
    if (lo == 0) gamma *= 0.1;  // no progress along steepest descent either: a shorter first step
    const Trial t = trial(lo);
    if (t == Trial::converged) return finish(true, "converged");
    if (t == Trial::budget) return finish(false, "max_evaluations");
    x0 = x;
    f0 = f;
    e0 = r.energy;
  }
}

}  // namespace mrf
