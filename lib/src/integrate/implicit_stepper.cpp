#include "mrf/integrate/implicit_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mrf/error.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/integrate/steps.hpp"
#include "parallel_blocks.hpp"

namespace mrf {

const char* to_string(ContactFormulation f) { return f == ContactFormulation::dual ? "dual" : "primal"; }

namespace {
// Milne's device for BDF2 against a quadratic extrapolation (equal steps):
// BDF2's local error is -(2/9) h^3 x''', the extrapolation's +h^3 x''', so
// the error is (2/9)/(1 + 2/9) = 2/11 of their difference.
constexpr double k_bdf2_error_constant = 2.0 / 11.0;
// Largest growth of the step from one accepted step to the next.
constexpr double k_max_growth = 2.0;
// After a Newton failure at dt, later steps stay below this fraction of
// it, a bound that relaxes by k_newton_cap_relax per accepted step: a failure
// costs max_newton iterations, so the controller does not walk back into it.
constexpr double k_newton_cap_after_failure = 0.8, k_newton_cap_relax = 1.02;
// A step shorter than this fraction of the largest allowed one is a failure.
constexpr double k_dt_floor = 1e-7;
// Spheres a thread takes at least in the step's passes over them (each
// sphere's own arithmetic: the same results on any number of threads).
constexpr std::size_t k_spheres_per_thread = 1024;

// x moved to the periodic image nearest `ref` (positions are wrapped each step).
Vec3 image_near(const Vec3& ref, const Vec3& x, const Box& box) { return ref - box.min_image(ref - x); }
}  // namespace

ImplicitStepper::ImplicitStepper(const ImplicitOptions& opt, const ImplicitContactParams& p, double dt_max,
                                 double near_reach)
    : opt_(opt), p_(p), dt_(dt_max), dt_max_(dt_max), dt_try_(0.1 * dt_max), near_reach_(near_reach) {}

const std::vector<Vec3>& ImplicitStepper::begin_step(const DemPairLists& lists, const FreeParticles& f,
                                                     const WallParticles& walls, const Box& box) {
  const double r = p_.radius, margin = k_contact_margin_over_radius * r;
  const double near_skin = near_reach_ - (2.0 * r + margin);
  if (near_x_.size() != f.size() ||
      skin_spent(2.0 * max_nonaffine_displacement(f.x, near_x_, box, near_strain_), near_strain_, near_reach_,
                 near_skin)) {
    near_pairs(lists.ff, f.x, box, near_reach_, near_ff_);
    near_x_ = f.x;
    near_strain_ = 0;
  }
  contact_candidates(near_ff_, lists.fw, f.x, walls, box, r, margin, candidates_);
  contact_forces(candidates_, f.x, walls, box, r, p_.hertz_k, fc_);
  x0_ = f.x;
  walls0_.x = walls.x;
  return fc_;
}

// One try of length dt from x0_; leaves y in f.x and the walls at t_{n+1}.
ImplicitStepper::Attempt ImplicitStepper::attempt(double dt, const ImplicitDrift& d, const NewtonOptions& nopt,
                                                  FreeParticles& f, WallParticles& walls, const Box& box) {
  const std::size_t n = f.size();
  const bool bdf2 = opt_.order == 2 && history_ >= 1;
  const double om = dt / dt_;
  const double c = bdf2 ? (1 + om) / (1 + 2 * om) : 1.0;
  const bool accelerating = !d.w1.empty(), carried = !d.u.empty();
  const double a1 = (1 + om) * (1 + om) / (1 + 2 * om), a2 = om * om / (1 + 2 * om);
  b_.resize(n);
  mob_.resize(n);
  if (carried) carrier_.resize(n);
  detail::for_each_index(n, k_spheres_per_thread, [&](std::size_t i) {
    mob_[i] = c * dt * d.inv_gamma[i];
    const Vec3 w = bdf2 ? Vec3((1 + om) * d.w0[i] - om * w_prev_[i]) : d.w0[i];
    if (carried) {
      carrier_[i] = dt * d.u[i];
      if (accelerating) carrier_[i] += (0.5 * dt * dt) * d.w1[i];
      b_[i] = bdf2 ? Vec3(a1 * x0_[i] - a2 * (image_near(x0_[i], x_prev_[i], box) + carrier_prev_[i]) + carrier_[i] +
                          c * dt * w)
                   : Vec3(x0_[i] + carrier_[i] + dt * w);
      return;
    }
    const Vec3 drift = accelerating ? Vec3(w + dt * d.w1[i]) : w;
    b_[i] = bdf2 ? Vec3(a1 * x0_[i] - a2 * image_near(x0_[i], x_prev_[i], box) + c * dt * drift)
                 : Vec3(x0_[i] + dt * drift);
  });
  // the fluid's response to the contact forces: over the whole step at its
  // end (c dt dt), or along the carrier's path (dt^2 / 2)
  const double response_scale = carried ? 0.5 * dt * dt : c * dt * dt;
  walls.x = walls0_.x;
  move_walls(walls, p_.shear_rate, dt);
  Attempt a;
  if (opt_.formulation == ContactFormulation::dual) {
    // Starts from the contact forces at x_n (walls at t_n).
    dual_.set_preconditioner(opt_.dual_preconditioner);
    a.newton = dual_.solve(candidates_, b_, x0_, walls0_, walls, box, p_.radius, p_.hertz_k, mob_, d.coupling,
                           response_scale, nopt, f.x);
  } else {
    if (d.coupling || std::any_of(d.inv_gamma.begin(), d.inv_gamma.end(),
                              [&](double g) { return g != d.inv_gamma.front(); }))
      throw InputError("numerics.implicit_formulation", "primal", "",
                       "the primal contact solver needs one mobility for all particles (model dem_stokes)");
    const double dt_over_gamma = n > 0 ? mob_.front() : 0.0;
    for (std::size_t i = 0; i < n; ++i) f.x[i] = x0_[i] + dt * f.v[i];  // predictor
    // Newton starts from the predictor or from x_n, whichever is lower in the
    // merit function: after a sudden change (a contact made or broken) the
    // extrapolated slope can throw the predictor far off.
    const double phi_pred = newton_.merit(candidates_, b_, walls, box, p_.radius, p_.hertz_k, dt_over_gamma, f.x);
    if (newton_.merit(candidates_, b_, walls, box, p_.radius, p_.hertz_k, dt_over_gamma, x0_) < phi_pred) f.x = x0_;
    a.newton = newton_.solve(candidates_, b_, walls, box, p_.radius, p_.hertz_k, dt_over_gamma, nopt, f.x);
  }
  counters_.newton_iterations += a.newton.iterations;
  counters_.linear_iterations += a.newton.linear_iterations;
  // Error: order 1, half the distance from the linear predictor x_n + dt v_n
  // ((dt/2)|v_{n+1} - v_n|); order 2, Milne's device on the quadratic through
  // x_{n-2}, x_{n-1}, x_n (Lagrange weights l0, l1, l2 at t_{n+1}).
  const bool quadratic = opt_.order == 2 && history_ >= 2;
  double l0 = 0, l1 = 0, l2 = 0;
  if (quadratic) {
    const double t0 = -(dt_ + dt_prev2_), t1 = -dt_;
    l0 = (dt - t1) * dt / ((t0 - t1) * t0);
    l1 = (dt - t0) * dt / ((t1 - t0) * t1);
    l2 = (dt - t0) * (dt - t1) / (t0 * t1);
  }
  if (carried && d.coupling) {  // D_n += (dt^2/2) C F_c
    contact_forces_end(f, walls, box, fc_scratch_);
    d.coupling->add(fc_scratch_, response_scale, carrier_);
  }
  // Positions relative to the carrier's position X at t_n: x_n itself,
  // x_{n-1} + D_{n-1}, x_{n-2} + D_{n-1} + D_{n-2}, and x - D_n at t_{n+1}.
  // The error and the largest step off the imposed flow, each sphere's own.
  const Vec3 zero = Vec3::Zero();
  a.error = detail::largest_of(n, k_spheres_per_thread, [&](std::size_t i) {
              const Vec3& dn = carried ? carrier_[i] : zero;
              const Vec3& d1 = carried && history_ >= 1 ? carrier_prev_[i] : zero;
              const Vec3& d2 = carried && history_ >= 2 ? carrier_prev2_[i] : zero;
              if (quadratic) {
                const Vec3 pred = l0 * (image_near(x0_[i], x_prev2_[i], box) + d1 + d2) +
                                  l1 * (image_near(x0_[i], x_prev_[i], box) + d1) + l2 * x0_[i];
                return k_bdf2_error_constant * (f.x[i] - dn - pred).norm();
              }
              // the last step's mean velocity relative to its carrier (at the
              // first step, relative to the carrier now)
              const Vec3 v_rel = !carried ? f.v[i] : history_ >= 1 ? Vec3(f.v[i] - d1 / dt_) : Vec3(f.v[i] - d.u[i]);
              return 0.5 * (f.x[i] - x0_[i] - dn - dt * v_rel).norm();
            }).v;
  const detail::Largest moved = detail::largest_of(n, k_spheres_per_thread, [&](std::size_t i) {
    Vec3 step = f.x[i] - x0_[i];
    step.z() -= p_.shear_rate * dt * x0_[i].x();  // less the affine part (the candidates' bound)
    return step.norm();
  });
  a.displacement = moved.v;
  if (moved.at < n) a.moved = static_cast<std::uint32_t>(moved.at);
  return a;
}

double ImplicitStepper::advance(const ImplicitDrift& d, FreeParticles& f, WallParticles& walls, const Box& box,
                                double time, long step, double dt_cap) {
  const double r = p_.radius, margin = k_contact_margin_over_radius * r;
  const NewtonOptions nopt{opt_.newton_tol_over_radius * r, opt_.max_newton, opt_.linear_rtol, opt_.solver};
  const double dt_max = std::min(dt_max_, dt_cap);
  // Land on the stop time without leaving a sliver for the next step.
  const double remaining = stop_time_ - time;
  double dt = opt_.fixed_step ? dt_max : std::min(dt_try_, dt_max);
  if (!opt_.fixed_step && remaining > 0 && remaining < 1.5 * dt) dt = remaining <= dt_max ? remaining : 0.5 * remaining;
  const double dt_floor = k_dt_floor * std::min(dt, dt_max);
  // The local error scales as dt^2 (order 1) or dt^3 (order 2).
  const double exponent = opt_.order == 2 && history_ >= 2 ? -1.0 / 3.0 : -0.5;
  bool retried = false;
  for (;;) {
    const Attempt a = attempt(dt, d, nopt, f, walls, box);
    // The contact candidates of x_n (pairs within 2R + margin) hold all
    // contacts of the step while no pair closes by more than the margin:
    // two non-affine displacements plus the imposed flow's change of the
    // separation (strain times at most 2R + margin; the walls move affinely).
    const bool too_far = 2.0 * a.displacement + std::abs(p_.shear_rate * dt) * (2.0 * r + margin) > margin;
    const double ratio = a.error / (opt_.tol_over_radius * r);
    if (opt_.fixed_step && (!a.newton.converged || too_far)) {
      std::ostringstream m;
      m << "implicit fixed step " << dt << " s failed at step " << step << " (t = " << time << " s): "
        << (a.newton.converged ? "particle " + std::to_string(a.moved) + " moved " + std::to_string(a.displacement / r) +
                                     " R off the imposed flow: a pair may close by more than the contact margin"
                               : "Newton did not converge; largest correction at particle " +
                                     std::to_string(a.newton.worst));
      throw NumericalError(m.str());
    }
    if (a.newton.converged && !too_far && (ratio <= 1.0 || opt_.fixed_step)) {
      detail::for_each_index(f.size(), k_spheres_per_thread, [&](std::size_t i) { f.v[i] = (f.x[i] - x0_[i]) / dt; });
      // No growth right after a rejection (Hairer & Wanner's rule: the step
      // that just failed is a better guess than the error model), nor after
      // a Newton solve that took more than half its iterations (a longer
      // step would likely fail to converge, and a failure costs them all).
      const double growth = retried || 2 * a.newton.iterations > opt_.max_newton ? 1.0 : k_max_growth;
      dt_try_ = std::min(dt_max_, dt * std::min(growth, 0.9 * std::pow(std::max(ratio, 1e-6), exponent)));
      newton_cap_ *= k_newton_cap_relax;
      dt_try_ = std::min(dt_try_, newton_cap_);
      x_prev2_.swap(x_prev_);
      x_prev_ = x0_;
      w_prev_ = d.w0;
      if (!d.u.empty()) {
        carrier_prev2_.swap(carrier_prev_);
        carrier_prev_ = carrier_;
      }
      dt_prev2_ = dt_;
      history_ = std::min(history_ + 1, 2);
      break;
    }
    ++(a.newton.converged ? counters_.rejected : counters_.newton_failures);
    if (!a.newton.converged) newton_cap_ = k_newton_cap_after_failure * dt;
    retried = true;
    dt *= !a.newton.converged ? 0.25 : too_far ? 0.5 : std::max(0.2, 0.9 * std::pow(ratio, exponent));
    if (!(dt >= dt_floor)) {
      std::ostringstream m;
      m << "implicit step failed at step " << step << " (t = " << time << " s): the step size fell to " << dt
        << " s (below " << k_dt_floor << " of the largest step " << dt_max << " s) without meeting the error"
        << " tolerance or a converged Newton solve; last Newton correction largest at particle " << a.newton.worst;
      throw NumericalError(m.str());
    }
  }
  dt_ = dt;
  near_strain_ += p_.shear_rate * dt;
  counters_.dt_min = std::min(counters_.dt_min, dt);
  counters_.dt_max = std::max(counters_.dt_max, dt);
  return dt;
}

void ImplicitStepper::contact_forces_end(const FreeParticles& f, const WallParticles& walls, const Box& box,
                                         std::vector<Vec3>& out) const {
  if (opt_.formulation == ContactFormulation::dual) {
    out.assign(f.size(), Vec3::Zero());
    dual_.add_forces(candidates_, out);
  } else {
    contact_forces(candidates_, f.x, walls, box, p_.radius, p_.hertz_k, out);
  }
}

}  // namespace mrf
