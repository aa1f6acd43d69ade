#include "mrf/integrate/stability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"
#include "mrf/io/quantity.hpp"

namespace mrf {

double verlet_exp_amplification(double omega, double tau, double dt) {
  // The scheme of steps.hpp on r'' = -omega^2 r - r'/tau, per unit mass:
  // w = -omega^2 tau r.
  const double w2t = omega * omega * tau;
  const double a = std::exp(-dt / tau), one_minus_a = -std::expm1(-dt / tau);
  const double c = exp_verlet_weight(dt / tau);
  auto step = [&](double r, double v) {
    const double w = -w2t * r;
    const double r1 = r + tau * one_minus_a * v + dt * c * w;
    const double v1 = a * v + one_minus_a * w + c * (-w2t * r1 - w);
    return Eigen::Vector2d(r1, v1);
  };
  Eigen::Matrix2d m;
  m.col(0) = step(1.0, 0.0);
  m.col(1) = step(0.0, 1.0);
  return m.eigenvalues().cwiseAbs().maxCoeff();
}

double verlet_exp_oscillator_limit(double omega, double tau) {
  // Scan upward on a log grid from well inside the stable range, then bisect
  // the first crossing of spectral radius 1.
  const double start = 1e-3 * std::min(1.0 / omega, tau);
  constexpr double k_ratio = 1.02;
  constexpr double k_tol = 1e-9;
  double lo = start;
  for (int i = 0; i < 4000; ++i) {
    const double hi = lo * k_ratio;
    if (verlet_exp_amplification(omega, tau, hi) > 1.0 + k_tol) {
      double a = lo, b = hi;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (a + b);
        (verlet_exp_amplification(omega, tau, mid) > 1.0 + k_tol ? b : a) = mid;
      }
      return a;
    }
    lo = hi;
  }
  return std::numeric_limits<double>::infinity();
}

double overdamped_contact_limit(double gamma, double k_eff) { return gamma / k_eff; }

namespace {
// A free pair in contact: relative coordinate with reduced mass m/2 and the
// same relaxation time, so omega^2 = 2 k_eff / m.
double contact_limit(const DemParams& p, IntegratorId scheme, double k_eff) {
  if (scheme == IntegratorId::implicit) return std::numeric_limits<double>::infinity();
  if (scheme == IntegratorId::overdamped) return overdamped_contact_limit(p.gamma, k_eff);
  return verlet_exp_oscillator_limit(std::sqrt(2.0 * k_eff / p.mass), p.tau_p);
}
}  // namespace

double contact_limit_at_overlap(const DemParams& p, IntegratorId scheme, double overlap) {
  const double k_eff = hertz_local_stiffness(overlap, p.hertz_k);
  return k_eff > 0 ? contact_limit(p, scheme, k_eff) : std::numeric_limits<double>::infinity();
}

double expected_overlap(const DemParams& p, IntegratorId scheme) {
  const double h_load = hertz_overlap_under_load(p.expected_load, p.hertz_k);
  if (scheme != IntegratorId::verlet_exp) return h_load;  // no inertia: overlap follows the load
  return std::max(h_load, hertz_max_overlap(0.5 * p.mass, p.impact_speed, p.hertz_k));
}

std::vector<StabilityLimit> dem_limits(const DemParams& p, double gap, IntegratorId scheme) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<StabilityLimit> out;
  const double h = expected_overlap(p, scheme);
  const bool inertial = scheme == IntegratorId::verlet_exp;
  out.push_back({"hertz contact", contact_limit_at_overlap(p, scheme, h),
                 (scheme == IntegratorId::implicit ? "backward Euler contacts, no limit; expected overlap/R "
                                                   : "expected overlap/R ") +
                     format_short(h / p.radius, 3) + " (load " + format_short(p.expected_load, 3) + " N" +
                     (inertial ? ", impact at " + format_short(p.impact_speed, 3) + " m/s" : "") + ")"});
  out.push_back({"drag relaxation", inf,
                 "tau_p = " + format_short(p.tau_p, 3) + (inertial ? " s (integrated exactly)" : " s (inertia neglected)")});
  if (scheme == IntegratorId::implicit) {
    // The implicit scheme's step is chosen by its error control; these bound
    // it from above. Explicit dipoles: the transverse (aligning) stiffness of
    // a head-to-tail pair at contact is F/(2R), and the alternating mode of a
    // chain relaxes at 4 (F/2R)/gamma, so explicit Euler on it is stable for
    // dt < gamma R / F. (BDF2's extrapolated explicit part has a smaller
    // stability interval, about half.) Contact candidates: the imposed flow
    // must not close a pair by more than the candidate margin in one step,
    // |gdot| dt (2R + margin) <= margin (integrate/implicit_stepper.cpp), or
    // a contact could be missed.
    if (p.contact_force > 0)
      out.push_back({"dipole stability", p.gamma * p.radius / p.contact_force,
                     "explicit dipoles, aligning mode of a chain: gamma R / F_contact"});
    if (p.shear_rate > 0)
      out.push_back({"contact margin",
                     k_contact_margin_over_radius / ((2.0 + k_contact_margin_over_radius) * std::abs(p.shear_rate)),
                     "the imposed flow closes a pair by at most the candidate margin (" +
                         format_short(k_contact_margin_over_radius, 3) + " R) per step"});
    return out;
  }
  // Accuracy bounds: a contact pair under the head-to-tail force, or a wall
  // sphere, moves at most 5 % of R per step.
  constexpr double k_frac = 0.05;
  if (p.contact_force > 0)
    out.push_back({"magnetic motion", k_frac * p.radius * p.gamma / (2.0 * p.contact_force),
                   "5 % of R per step at the contact force"});
  if (p.shear_rate > 0)
    out.push_back({"shear (wall motion)", k_frac * p.radius / wall_speed(p.shear_rate, gap),
                   "5 % of R per step at the wall speed"});
  return out;
}

IntegratorId auto_integrator(const std::vector<StabilityLimit>& verlet_exp,
                             const std::vector<StabilityLimit>& overdamped,
                             const std::vector<StabilityLimit>& implicit, double stokes_number) {
  if (stokes_number > k_inertialess_max_stokes) return IntegratorId::verlet_exp;
  const double explicit_dt = std::max(smallest(verlet_exp), smallest(overdamped));
  if (k_implicit_preference * explicit_dt < smallest(implicit)) return IntegratorId::implicit;
  return smallest(verlet_exp) >= smallest(overdamped) ? IntegratorId::verlet_exp : IntegratorId::overdamped;
}

double critical_overlap(const DemParams& p, IntegratorId scheme, double dt) {
  // contact_limit_at_overlap decreases with overlap; bisect in log space.
  double lo = 1e-16 * p.radius, hi = p.radius;
  if (contact_limit_at_overlap(p, scheme, hi) >= dt) return hi;
  if (contact_limit_at_overlap(p, scheme, lo) < dt) return lo;
  for (int it = 0; it < 80; ++it) {
    const double mid = std::sqrt(lo * hi);
    (contact_limit_at_overlap(p, scheme, mid) >= dt ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace mrf
