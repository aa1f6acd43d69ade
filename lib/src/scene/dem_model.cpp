#include "mrf/scene/dem_model.hpp"

#include <cmath>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"

namespace mrf {

DemModel::DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt)
    : cell_(std::move(cell)), p_(params), scheme_(scheme), dt_(dt) {
  if (scheme_ != IntegratorId::verlet_exp && scheme_ != IntegratorId::overdamped)
    throw InputError("numerics.integrator", to_string(scheme_), "", "not available for dem_stokes yet");
  cell_.free.v.resize(cell_.free.size(), Vec3::Zero());
  cell_.free.f.resize(cell_.free.size(), Vec3::Zero());
  const double two_r = 2.0 * p_.radius;
  const double ff_range = p_.dipole_pref > 0 ? std::max(p_.dipole_cutoff, two_r) : two_r;
  lists_ = make_pair_lists(ff_range, cell_.walls.size() > 0 ? two_r : 0.0, p_.skin);
  overlap_limit_ = critical_overlap(p_, scheme_, dt_);
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
