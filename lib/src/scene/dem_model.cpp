#include "mrf/scene/dem_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mrf/error.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

namespace {
// Starting skin of the implicit scheme where the box allows (dem_pair_lists);
// the adaptive choice moves it from the first rebuild on. (Measured before
// the skin was adaptive: 0.8 R rebuilt 41 of 80 steps on the paper scene at
// Mn = 1e-2 against 73 of 80 for 0.4 R.)
constexpr double k_implicit_skin_over_radius = 0.8;
// Skin of the near list of contact candidates (a refresh scans the dipole list).
constexpr double k_near_skin_over_radius = 1.0;
// Smallest skin an adaptive choice may take.
constexpr double k_min_skin_over_radius = 0.05;
}  // namespace

DemPairLists dem_pair_lists(const DemParams& p, const Box& box, bool implicit, bool walls, double& near_reach) {
  const double two_r = 2.0 * p.radius;
  const double contact_reach = implicit ? two_r + k_contact_margin_over_radius * p.radius : two_r;
  const double ff_range = p.dipole_pref > 0 ? std::max(p.dipole_cutoff, contact_reach) : contact_reach;
  // An adaptive skin starts from 0.2 R, or for the implicit scheme, whose
  // steps are long, from k_implicit_skin_over_radius where the minimum
  // image allows; a skin the scene gives is kept.
  const double largest = 0.5 * std::min(box.ly, box.lz) - ff_range;
  double skin = p.skin;
  if (implicit && p.adaptive_skin) skin = std::max(skin, std::min(k_implicit_skin_over_radius * p.radius, largest));
  near_reach = std::min(ff_range, contact_reach + k_near_skin_over_radius * p.radius);
  SkinPolicy policy;
  policy.adaptive = p.adaptive_skin;
  policy.min = std::min(k_min_skin_over_radius * p.radius, skin);
  policy.max = std::max(largest, skin);
  return make_pair_lists(ff_range, walls ? contact_reach : 0.0, skin, policy);
}

ImplicitContactParams implicit_contact_params(const DemParams& p) { return {p.radius, p.hertz_k, p.shear_rate}; }

DemModel::DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt)
    : cell_(std::move(cell)), p_(params), scheme_(scheme), dt_(dt) {
  if (scheme_ == IntegratorId::automatic)
    throw InputError("numerics.integrator", to_string(scheme_), "", "choose the integrator before building the model");
  cell_.free.v.resize(cell_.free.size(), Vec3::Zero());
  cell_.free.f.resize(cell_.free.size(), Vec3::Zero());
  const bool implicit = scheme_ == IntegratorId::implicit;
  double near_reach = 0;
  lists_ = dem_pair_lists(p_, cell_.box, implicit, cell_.walls.size() > 0, near_reach);
  if (implicit) {
    implicit_.emplace(ImplicitOptions{}, implicit_contact_params(p_), dt, near_reach);
    drift_.inv_gamma.assign(cell_.free.size(), 1.0 / p_.gamma);
  }
  overlap_limit_ = scheme_ == IntegratorId::implicit ? p_.radius : critical_overlap(p_, scheme_, dt_);
  update_forces();
}

void DemModel::update_forces() {
  check_finite_positions();
  wrap_all(cell_.free.x, cell_.box);
  wrap_all(cell_.walls.x, cell_.box);
  build_pair_lists(lists_, cell_.free, cell_.walls, cell_.box);  // rebuilds only the lists that may be stale
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
  advance_pair_lists(lists_, p_.shear_rate * dt_);
  time_ += dt_;
  ++steps_;
  update_forces();
  if (scheme_ == IntegratorId::verlet_exp)
    exp_verlet_correct(f.x, f.v, f.f, w_, p_.tau_p, p_.gamma, p_.shear_rate, dt_);
}

// IMEX Euler or BDF2 on dx/dt = u(x) + (F_nc + F_c)/gamma with the contacts
// F_c implicit (integrate/implicit_stepper.hpp), one accepted step.
void DemModel::implicit_step() {
  auto& f = cell_.free;
  const std::vector<Vec3>& fc = implicit_->begin_step(lists_, f, cell_.walls, cell_.box);
  drift_.w0.resize(f.size());  // explicit drift u(x_n) + F_nc(x_n)/gamma, F_nc = F - F_c
  for (std::size_t i = 0; i < f.size(); ++i)
    drift_.w0[i] = drift_velocity(f.x[i], f.f[i] - fc[i], 1.0 / p_.gamma, p_.shear_rate);
  const double dt = implicit_->advance(drift_, f, cell_.walls, cell_.box, time_, steps_);
  advance_pair_lists(lists_, p_.shear_rate * dt);
  time_ += dt;
  ++steps_;
  update_forces();
}

StepSample DemModel::sample() const {
  const double eta_gdot = imposed_fluid_stress(p_.viscosity, p_.shear_rate);  // the imposed profile transmits it
  return {sums_, eta_gdot, eta_gdot, implicit_ ? implicit_->dt() : 1.0};
}

void DemModel::finish(RunSummary& s) const {
  if (implicit_) report_implicit(implicit_->counters(), s);
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
      << overlap_limit_ / p_.radius << ", the largest overlap dt = " << dt()
      << " s keeps stable; lower numerics.dt or numerics.dt_safety";
    throw NumericalError(s.str());
  }
}

}  // namespace mrf
