#include "mrf/scene/dem_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mrf/error.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"

namespace mrf {

const char* to_string(ContactFormulation f) { return f == ContactFormulation::dual ? "dual" : "primal"; }

namespace {
// Contact candidates of an implicit step are the pairs within 2R + margin at
// x_n (margin = k_contact_margin_over_radius R, stability.hpp); a step that
// moves a particle (or the walls) by more than margin/2 is rejected, so no
// contact can be missed. Lists are built with this reach.
// Verlet skin of the implicit scheme where the box allows (see the constructor).
constexpr double k_implicit_skin_over_radius = 0.4;
// Skin of the near list of contact candidates (a refresh scans the dipole list).
constexpr double k_near_skin_over_radius = 1.0;
// Milne's device for BDF2 against a quadratic extrapolation (equal steps):
// BDF2's local error is -(2/9) h^3 x''', the extrapolation's +h^3 x''', so
// the error is (2/9)/(1 + 2/9) = 2/11 of their difference.
constexpr double k_bdf2_error_constant = 2.0 / 11.0;
// A step shorter than this fraction of the largest allowed one is a failure.
constexpr double k_dt_floor = 1e-7;
}  // namespace

DemModel::DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt)
    : cell_(std::move(cell)), p_(params), scheme_(scheme), dt_(dt), dt_max_(dt), dt_try_(0.1 * dt) {
  if (scheme_ == IntegratorId::automatic)
    throw InputError("numerics.integrator", to_string(scheme_), "", "choose the integrator before building the model");
  cell_.free.v.resize(cell_.free.size(), Vec3::Zero());
  cell_.free.f.resize(cell_.free.size(), Vec3::Zero());
  const double two_r = 2.0 * p_.radius;
  const double contact_reach =
      scheme_ == IntegratorId::implicit ? two_r + k_contact_margin_over_radius * p_.radius : two_r;
  const double ff_range = p_.dipole_pref > 0 ? std::max(p_.dipole_cutoff, contact_reach) : contact_reach;
  // An implicit step moves particles up to half the contact margin, so a
  // 0.2 R skin would be rebuilt almost every step: it is raised to 0.4 R
  // where the minimum image allows.
  double skin = p_.skin;
  if (scheme_ == IntegratorId::implicit)
    skin = std::max(skin, std::min(k_implicit_skin_over_radius * p_.radius,
                                   0.5 * std::min(cell_.box.ly, cell_.box.lz) - ff_range));
  lists_ = make_pair_lists(ff_range, cell_.walls.size() > 0 ? contact_reach : 0.0, skin);
  near_reach_ = std::min(ff_range, contact_reach + k_near_skin_over_radius * p_.radius);
  overlap_limit_ = scheme_ == IntegratorId::implicit ? p_.radius : critical_overlap(p_, scheme_, dt_);
  update_forces();
}

void DemModel::update_forces() {
  check_finite_positions();
  wrap_all(cell_.free.x, cell_.box);
  wrap_all(cell_.walls.x, cell_.box);
  if (needs_rebuild(lists_, cell_.free, cell_.box)) build_pair_lists(lists_, cell_.free, cell_.walls, cell_.box);
  sums_ = compute_dem_forces(p_, cell_.box, cell_.free, cell_.walls, lists_, buffers_);
  check_finite();
}

void DemModel::step() {
  if (scheme_ == IntegratorId::implicit) return implicit_step();
  auto& f = cell_.free;
  if (scheme_ == IntegratorId::verlet_exp) {
    exp_verlet_advance(f.x, f.v, f.f, w_, p_.tau_p, p_.gamma, p_.shear_rate, dt_);
  } else {
    overdamped_drift(f.x, f.v, f.f, p_.gamma, p_.shear_rate, dt_);
  }
  move_walls(cell_.walls, p_.shear_rate, dt_);
  lists_.wall_travel += std::abs(p_.shear_rate) * 0.5 * cell_.box.gap * dt_;
  time_ += dt_;
  ++steps_;
  update_forces();
  if (scheme_ == IntegratorId::verlet_exp)
    exp_verlet_correct(f.x, f.v, f.f, w_, p_.tau_p, p_.gamma, p_.shear_rate, dt_);
}

namespace {
// x moved to the periodic image nearest `ref` (positions are wrapped each step).
Vec3 image_near(const Vec3& ref, const Vec3& x, const Box& box) { return ref - box.min_image(ref - x); }
}  // namespace

// One try of an implicit step of length dt from x0_ (explicit drift in w_):
// Newton for y = b + (c dt/gamma) F_c(y), walls at t_{n+1}; IMEX Euler:
// b = x_n + dt w_n, c = 1; BDF2 with omega = dt/dt_{n-1}:
//   b = a1 x_n - a2 x_{n-1} + c dt ((1 + omega) w_n - omega w_{n-1}),
//   a1 = (1+omega)^2/(1+2 omega), a2 = omega^2/(1+2 omega), c = (1+omega)/(1+2 omega).
// Leaves y in free.x; returns the Newton result, the error estimate and the
// largest displacement.
DemModel::Attempt DemModel::attempt(double dt, const NewtonOptions& nopt) {
  auto& f = cell_.free;
  const std::size_t n = f.size();
  const bool bdf2 = opt_.order == 2 && history_ >= 1;
  const double om = dt / dt_;
  const double c = bdf2 ? (1 + om) / (1 + 2 * om) : 1.0;
  const double dt_over_gamma = c * dt / p_.gamma;
  b_.resize(n);
  if (bdf2) {
    const double a1 = (1 + om) * (1 + om) / (1 + 2 * om), a2 = om * om / (1 + 2 * om);
    for (std::size_t i = 0; i < n; ++i)
      b_[i] = a1 * x0_[i] - a2 * image_near(x0_[i], x_prev_[i], cell_.box) +
              c * dt * ((1 + om) * w_[i] - om * w_prev_[i]);
  } else {
    for (std::size_t i = 0; i < n; ++i) b_[i] = x0_[i] + dt * w_[i];
  }
  cell_.walls.x = walls0_.x;
  move_walls(cell_.walls, p_.shear_rate, dt);
  Attempt a;
  if (opt_.formulation == ContactFormulation::dual) {
    // Starts from the contact forces at x_n (walls at t_n).
    a.newton = dual_.solve(candidates_, b_, x0_, walls0_, cell_.walls, cell_.box, p_.radius, p_.hertz_k, dt_over_gamma,
                           nopt, f.x);
  } else {
    for (std::size_t i = 0; i < n; ++i) f.x[i] = x0_[i] + dt * f.v[i];  // predictor
    // Newton starts from the predictor or from x_n, whichever is lower in the
    // merit function: after a sudden change (a contact made or broken) the
    // extrapolated slope can throw the predictor far off.
    const double phi_pred =
        newton_.merit(candidates_, b_, cell_.walls, cell_.box, p_.radius, p_.hertz_k, dt_over_gamma, f.x);
    if (newton_.merit(candidates_, b_, cell_.walls, cell_.box, p_.radius, p_.hertz_k, dt_over_gamma, x0_) < phi_pred)
      f.x = x0_;
    a.newton = newton_.solve(candidates_, b_, cell_.walls, cell_.box, p_.radius, p_.hertz_k, dt_over_gamma, nopt, f.x);
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
  for (std::size_t i = 0; i < n; ++i) {
    if (quadratic) {
      const Vec3 pred = l0 * image_near(x0_[i], x_prev2_[i], cell_.box) +
                        l1 * image_near(x0_[i], x_prev_[i], cell_.box) + l2 * x0_[i];
      a.error = std::max(a.error, k_bdf2_error_constant * (f.x[i] - pred).norm());
    } else {
      a.error = std::max(a.error, 0.5 * (f.x[i] - x0_[i] - dt * f.v[i]).norm());
    }
    const double d = (f.x[i] - x0_[i]).norm();
    if (d > a.displacement) a.displacement = d, a.moved = static_cast<std::uint32_t>(i);
  }
  return a;
}

// IMEX Euler or BDF2 (REFERENCE §3, contacts implicit), one accepted step:
//   y = x_n + dt (u(x_n) + F_nc(x_n)/gamma) + (dt/gamma) F_c(y)   (order 1; order 2: attempt()),
// error-controlled (ImplicitOptions): a step is retried shorter when Newton
// fails (dt/4), a particle or the walls move more than half the contact
// margin (dt/2), or the error estimate exceeds the tolerance.
void DemModel::implicit_step() {
  auto& f = cell_.free;
  const double r = p_.radius, margin = k_contact_margin_over_radius * r;
  const double wall_speed = std::abs(p_.shear_rate) * 0.5 * cell_.box.gap;
  const double near_skin = near_reach_ - (2.0 * r + margin);
  if (near_x_.size() != f.size() || 2.0 * max_displacement(f.x, near_x_, cell_.box) > near_skin) {
    near_pairs(lists_.ff, f.x, cell_.box, near_reach_, near_ff_);
    near_x_ = f.x;
  }
  contact_candidates(near_ff_, lists_.fw, f.x, cell_.walls, cell_.box, r, margin, candidates_);
  contact_forces(candidates_, f.x, cell_.walls, cell_.box, r, p_.hertz_k, fc_);
  x0_ = f.x;
  walls0_.x = cell_.walls.x;
  w_.resize(f.size());  // explicit drift u(x_n) + F_nc(x_n)/gamma, F_nc = F - F_c
  for (std::size_t i = 0; i < f.size(); ++i)
    w_[i] = drift_velocity(x0_[i], f.f[i] - fc_[i], 1.0 / p_.gamma, p_.shear_rate);
  const NewtonOptions nopt{opt_.newton_tol_over_radius * r, opt_.max_newton, opt_.linear_rtol, opt_.solver};
  // Land on the stop time without leaving a sliver for the next step.
  const double remaining = stop_time_ - time_;
  double dt = opt_.fixed_step ? dt_max_ : dt_try_;
  if (!opt_.fixed_step && remaining > 0 && remaining < 1.5 * dt_try_)
    dt = remaining <= dt_max_ ? remaining : 0.5 * remaining;
  const double dt_floor = k_dt_floor * std::min(dt, dt_max_);
  for (;;) {
    const Attempt a = attempt(dt, nopt);
    const bool too_far = a.displacement > 0.5 * margin || wall_speed * dt > 0.5 * margin;
    const double ratio = a.error / (opt_.tol_over_radius * r);
    if (opt_.fixed_step && (!a.newton.converged || too_far)) {
      std::ostringstream m;
      m << "implicit fixed step " << dt << " s failed at step " << steps_ << " (t = " << time_ << " s): "
        << (a.newton.converged ? "particle " + std::to_string(a.moved) + " moved " + std::to_string(a.displacement / r) +
                                     " R, more than half the contact margin"
                               : "Newton did not converge; largest correction at particle " +
                                     std::to_string(a.newton.worst));
      throw NumericalError(m.str());
    }
    // The local error scales as dt^2 (order 1) or dt^3 (order 2).
    const double exponent = opt_.order == 2 && history_ >= 2 ? -1.0 / 3.0 : -0.5;
    if (a.newton.converged && !too_far && (ratio <= 1.0 || opt_.fixed_step)) {
      for (std::size_t i = 0; i < f.size(); ++i) f.v[i] = (f.x[i] - x0_[i]) / dt;
      dt_try_ = std::min(dt_max_, dt * std::min(2.0, 0.9 * std::pow(std::max(ratio, 1e-6), exponent)));
      if (opt_.order == 2) {
        x_prev2_.swap(x_prev_);
        x_prev_ = x0_;
        w_prev_ = w_;
        dt_prev2_ = dt_;
        history_ = std::min(history_ + 1, 2);
      }
      break;
    }
    ++(a.newton.converged ? counters_.rejected : counters_.newton_failures);
    dt *= !a.newton.converged ? 0.25 : too_far ? 0.5 : std::max(0.2, 0.9 * std::pow(ratio, exponent));
    if (!(dt >= dt_floor)) {
      std::ostringstream m;
      m << "implicit step failed at step " << steps_ << " (t = " << time_ << " s): the step size fell to " << dt
        << " s (below " << k_dt_floor << " of numerics.dt " << dt_max_ << " s) without meeting the error tolerance"
        << " or a converged Newton solve; last Newton correction largest at particle " << a.newton.worst;
      throw NumericalError(m.str());
    }
  }
  dt_ = dt;
  counters_.dt_min = std::min(counters_.dt_min, dt);
  counters_.dt_max = std::max(counters_.dt_max, dt);
  lists_.wall_travel += wall_speed * dt;
  time_ += dt;
  ++steps_;
  update_forces();
}

void DemModel::check_finite_positions() const {
  const auto& f = cell_.free;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!f.x[i].allFinite() || !f.v[i].allFinite()) {
      std::ostringstream s;
      s << "non-finite " << (f.x[i].allFinite() ? "velocity" : "position") << " of particle " << i
        << " at step " << steps_ << " (t = " << time_ << " s)";
      throw NumericalError(s.str());
    }
}

// Positions were checked before binning; here the forces they produced.
void DemModel::check_finite() const {
  const auto& f = cell_.free;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.f[i].allFinite()) {
      std::ostringstream s;
      s << "non-finite force on particle " << i << " at step " << steps_ << " (t = " << time_ << " s)";
      throw NumericalError(s.str());
    }
  }
  if (sums_.max_overlap > overlap_limit_) {
    std::ostringstream s;
    s << "contact stability limit exceeded at step " << steps_ << " (t = " << time_
      << " s): overlap/R = " << sums_.max_overlap / p_.radius << " > "
      << overlap_limit_ / p_.radius << ", the largest overlap dt = " << dt_
      << " s keeps stable; lower numerics.dt or numerics.dt_safety";
    throw NumericalError(s.str());
  }
}

}  // namespace mrf
