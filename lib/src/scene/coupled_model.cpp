#include "mrf/scene/coupled_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "mrf/coupling/drag_laws.hpp"
#include "mrf/error.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/fluid/viscosity.hpp"
#include "mrf/fluid/wcsph.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/integrate/steps.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/fluid_only.hpp"
#include "mrf/scene/run_series.hpp"
#include "coupling/dem_runs.hpp"

namespace mrf {

namespace {

Vec3 sum_of(const std::vector<Vec3>& f) {
  Vec3 s = Vec3::Zero();
  for (const Vec3& x : f) s += x;
  return s;
}

// sum over fluid-fluid and fluid-wall pairs of r_ab,x F_ab,z (N m), F_ab the
// pressure + viscous force on a from b, as in add_pressure_acceleration and
// add_viscous_acceleration.
double fluid_pair_virial_xz(const FluidCell& c) {
  const auto& f = c.fluid;
  double sum = 0.0;
  for (const SphPair& pr : c.pairs.fluid_fluid) {
    const Vec3 a = pressure_pair_acceleration(c.mass, f.p[pr.a], f.rho[pr.a], f.p[pr.b], f.rho[pr.b], pr.r_ab, pr.r,
                                              c.h) +
                   morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), f.rho[pr.a], f.rho[pr.b]) *
                       (f.v[pr.a] - f.v[pr.b]);
    sum += pr.r_ab.x() * c.mass * a.z();
  }
  for (const SphPair& pr : c.pairs.fluid_wall) {
    const Vec3 a = pressure_pair_acceleration(c.mass, f.p[pr.a], f.rho[pr.a], c.wall.p[pr.b], c.wall.rho[pr.b],
                                              pr.r_ab, pr.r, c.h) +
                   wall_viscous_acceleration(c, pr);
    // Only the part of the bond inside the volume counts (Irving-Kirkwood):
    // from the fluid particle to the wall plane, not to the wall particle
    // up to 2h behind it.
    sum += (c.fluid.x[pr.a].x() - c.wall.side[pr.b] * 0.5 * c.box.gap) * c.mass * a.z();
  }
  return sum;
}

}  // namespace

FluidCell build_coupled_fluid(const SceneConfig& c, const ShearCell& cell) {
  FluidCell f = build_fluid_cell(cell.box, fluid_params_from_scene(c));
  const double phi = static_cast<double>(cell.free.size()) * sphere_volume(c.radius) / cell.box.volume();
  f.mass *= 1.0 - phi;
  for (std::size_t a = 0; a < f.fluid.size(); ++a) f.fluid.v[a] = Vec3(0.0, 0.0, c.shear_rate * f.fluid.x[a].x());
  refresh(f);
  return f;
}

double coupled_viscous_limit(const FluidCell& f, double eps_min) {
  return 0.125 * f.h * f.h * eps_min * f.params.density / (f.params.viscosity * f.viscous_scale);
}

namespace {
CoupledStepping inertial_stepping(double dt_fluid, int substeps) {
  CoupledStepping s;
  s.dt_fluid = dt_fluid;
  s.substeps = substeps;
  return s;
}
}  // namespace

const char* to_string(CoupledScheme s) { return s == CoupledScheme::inertial ? "inertial" : "inertialess"; }

CoupledModel::CoupledModel(ShearCell cell, const DemParams& params, FluidCell fluid, CoupledDrag law,
                           double dt_fluid, int substeps)
    : CoupledModel(std::move(cell), params, std::move(fluid), law, inertial_stepping(dt_fluid, substeps)) {}

CoupledModel::CoupledModel(ShearCell cell, const DemParams& params, FluidCell fluid, CoupledDrag law,
                           const CoupledStepping& stepping)
    : cell_(std::move(cell)),
      p_(params),
      fluid_(std::move(fluid)),
      law_(law),
      dt_(stepping.dt_fluid),
      substeps_(stepping.substeps),
      stepping_(stepping) {
  const bool inertialess = stepping_.scheme == CoupledScheme::inertialess;
  if (!(dt_ > 0) || substeps_ < 1 || (inertialess && !(stepping_.dt_max > 0)))
    throw InputError("numerics.dt", std::to_string(inertialess ? stepping_.dt_max : dt_), "",
                     "coupled step must be > 0");
  const std::size_t n = cell_.free.size();
  cell_.free.v.resize(n, Vec3::Zero());
  cell_.free.f.resize(n, Vec3::Zero());
  double near_reach = 0;
  lists_ = dem_pair_lists(p_, cell_.box, inertialess, cell_.walls.size() > 0, near_reach);
  sph_pairs_.skin = stepping_.sph_skin;
  coupling_cache_.skin = stepping_.coupling_skin;
  if (inertialess) {
    implicit_.emplace(stepping_.implicit, implicit_contact_params(p_), stepping_.dt_max, near_reach);
    overlap_limit_ = p_.radius;
  } else {
    overlap_limit_ = critical_overlap(p_, IntegratorId::verlet_exp, dt_dem());
  }
  parcel_.u.assign(n, Vec3::Zero());
  parcel_.impulse.assign(n, Vec3::Zero());
  // The EOS reference: rho0 for every SPH particle (the default, REFERENCE
  // §6), so the start's pressure moves the fluid into the porosity field
  // (toward the walls, where eps is higher than the mean 1 - phi the mass is
  // scaled by) and a fluid at rest has one intrinsic density; or each
  // particle's intrinsic density at the start, so the start carries no
  // pressure, but the particles carry the start's porosity field with them
  // (docs/study.md, "The carrier's wall layer").
  fluid_.fluid.rest_density.clear();
  update_coupling_pairs();
  fluid_.fluid.rest_density.resize(fluid_.fluid.size());
  for (std::size_t a = 0; a < fluid_.fluid.size(); ++a)
    fluid_.fluid.rest_density[a] = fluid_.params.common_eos_reference ? fluid_.params.density
                                                                       : fluid_.fluid.rho[a] / fluid_.fluid.eps[a];
  update_pressures(fluid_);
  update_dem_forces();
  momentum0_ = momentum();
}

StepSample CoupledModel::sample() const {
  return {sums_.dem, sums_.fluid_stress, sums_.fluid_virial + sums_.exchange_virial, implicit_ ? implicit_->dt() : 1.0};
}

std::string CoupledModel::progress() const {
  char b[48];
  std::snprintf(b, sizeof b, "eps %.3f-%.3f", sums_.eps_min, sums_.eps_max);
  return b;
}

void CoupledModel::finish(RunSummary& s) const {
  const Vec3 drift = momentum() - momentum0_ - external_impulse_;
  // the fluid's momentum at the wall speed
  const double scale = fluid_.mass * static_cast<double>(fluid_.fluid.size()) * wall_speed(p_.shear_rate, cell_.box.gap);
  s.extra["porosity_min"] = eps_seen_min_;
  s.extra["porosity_max"] = eps_seen_max_;
  s.extra["steps_with_clamped_porosity"] = static_cast<double>(clamped_steps_);
  s.extra["momentum_drift_N_s"] = drift.norm();
  s.extra["momentum_drift_relative"] = scale > 0 ? drift.norm() / scale : 0.0;
  s.extra["sph_wall_reflections"] = static_cast<double>(sums_.wall_reflections);
  s.extra["sph_wall_layer_fraction_end"] = wall_layer_fraction(fluid_);
  s.extra["coupling_pair_builds"] = static_cast<double>(coupling_cache_.builds);
  if (implicit_) {
    report_implicit(implicit_->counters(), s);
    s.extra["fluid_steps"] = static_cast<double>(fluid_substeps_);
    s.extra["sph_pair_builds"] = static_cast<double>(sph_pairs_.builds);
    if (stepping_.sph != SphImplicit::none) s.extra["viscous_cg_iterations"] = static_cast<double>(viscous_iterations_);
  } else {
    s.steps = steps_ * substeps_;  // DEM sub-steps
    s.extra["fluid_steps"] = static_cast<double>(steps_);
    // (no sph_pair_builds: this scheme's checkpoint does not keep its SPH
    // pair cache, so a resumed run would count one more build)
  }
}

Vec3 CoupledModel::momentum() const {
  const Vec3 fluid = fluid_.mass * sum_of(fluid_.fluid.v);
  return implicit_ ? fluid : Vec3(p_.mass * sum_of(cell_.free.v) + fluid);
}

// Pairs, porosity and pressures for the current DEM and SPH positions.
void CoupledModel::update_coupling_pairs() {
  // Porosity with the particles within 2h of a wall mirrored across its
  // plane: the part of their kernel beyond the wall, where no fluid samples
  // it, folds back into the fluid. Without it the fluid sees less solid
  // than there is once chains touch the walls, its mean intrinsic density
  // falls and the tension pulls SPH particles through the wall (seen at
  // Mn = 1e-2 after 4.5 strain units). One search serves both lists: the
  // mirror images have indices >= n, and pairs come sorted by index.
  // The pairs come from a Verlet cache (coupling/exchange.hpp) whose
  // points are the particles and the mirrors of those within reach of a
  // wall at its build; a mirror counts only while its particle is within
  // 2h of the wall, so the pairs equal a fresh search's.
  const std::size_t n = cell_.free.size();
  const double rc = k_kernel_support * fluid_.h, half = 0.5 * cell_.box.gap;
  const auto& x = cell_.free.x;
  auto mirror = [&](const Vec3& p) { return Vec3((p.x() > 0 ? 2.0 * half : -2.0 * half) - p.x(), p.y(), p.z()); };
  auto place = [&] {
    solid_.assign(x.begin(), x.end());
    for (std::uint32_t i : mirrored_) solid_.push_back(mirror(x[i]));
  };
  place();
  coupling_cache_.strain = p_.shear_rate * (time_ - coupling_cache_time_);
  if (coupling_cache_.skin <= 0 ||
      coupling_cache_stale(coupling_cache_, solid_, fluid_.fluid.x, cell_.box, fluid_.h)) {
    const double reach = rc + coupling_cache_.skin;
    mirrored_.clear();
    for (std::uint32_t i = 0; i < n; ++i)
      if (half - std::abs(x[i].x()) < reach) mirrored_.push_back(i);
    place();
    rebuild_coupling_cache(coupling_cache_, solid_, fluid_.fluid.x, cell_.box, fluid_.h);
    coupling_cache_time_ = time_;
  }
  coupling_pairs_of(coupling_cache_.candidates, solid_, fluid_.fluid.x, cell_.box, fluid_.h, solid_pairs_,
                    implicit_ ? &pair_grads_ : nullptr);
  // The pairs come in index order, the mirrors' (i >= n) last: only that
  // tail is filtered, and the particles' pairs are its prefix, kept by a
  // swap once the porosity has read the mirrors.
  const auto real_end = std::partition_point(solid_pairs_.begin(), solid_pairs_.end(),
                                             [n](const CouplingPair& q) { return q.i < n; });
  const auto n_real = real_end - solid_pairs_.begin();
  solid_pairs_.erase(std::remove_if(real_end, solid_pairs_.end(),
                                    [&](const CouplingPair& q) {
                                      return !(half - std::abs(x[mirrored_[q.i - n]].x()) < rc);
                                    }),
                     solid_pairs_.end());
  PorosityField eps = porosity_at_fluid(fluid_.fluid.size(), sphere_volume(p_.radius), solid_pairs_);
  solid_pairs_.resize(static_cast<std::size_t>(n_real));
  if (implicit_) pair_grads_.resize(static_cast<std::size_t>(n_real));  // the mirrors' gradients are not read
  pairs_.swap(solid_pairs_);
  fluid_.fluid.eps = std::move(eps.eps);
  sums_.eps_clamped = eps.clamped;
  const auto [lo, hi] = std::minmax_element(fluid_.fluid.eps.begin(), fluid_.fluid.eps.end());
  sums_.eps_min = lo == fluid_.fluid.eps.end() ? 1.0 : *lo;
  sums_.eps_max = hi == fluid_.fluid.eps.end() ? 1.0 : *hi;
  update_pressures(fluid_);
}

// Fluid fields at the particles (Shepard, REFERENCE §6), buoyancy, friction
// coefficient and parcel inertia, frozen for the coming fluid step.
// a_fluid: acceleration of every SPH particle from its own (non-coupling)
// forces; its pressure + viscous part times the superficial density is
// -grad p + div tau.
void CoupledModel::prepare_coupling(const std::vector<Vec3>& a_fluid) {
  const std::size_t n = cell_.free.size(), nf = fluid_.fluid.size();
  const auto& rho = fluid_.fluid.rho;
  shepard_ = shepard_interpolate(n, pairs_, fluid_.mass, rho, fluid_.fluid.v, fluid_.fluid.eps);
  const Vec3 g_body(0.0, 0.0, fluid_.params.body_force);
  // Omega_a = sum_j W_aj / s_j: how strongly the SPH particle a receives reactions.
  std::vector<double> omega(nf, 0.0);
  for (const CouplingPair& q : pairs_) omega[q.a] += q.w / shepard_.s[q.i];
  std::vector<Vec3> acc(n, Vec3::Zero()), a_pv(nf);
  std::vector<double> inv_m(n, 0.0);
  detail::by_dem_runs(pairs_, [&](std::uint32_t i, std::size_t first, std::size_t last) {
    Vec3 acc_i = acc[i];
    double inv_m_i = inv_m[i];
    for (std::size_t e = first; e < last; ++e) {
      const CouplingPair& q = pairs_[e];
      const double w = fluid_.mass * q.w / rho[q.a];  // Shepard weight (m/rho_a) W_ia
      acc_i += w * a_fluid[q.a];
      inv_m_i += w * omega[q.a] / rho[q.a];
    }
    acc[i] = acc_i, inv_m[i] = inv_m_i;
  });
  for (std::size_t b = 0; b < nf; ++b) a_pv[b] = a_fluid[b] - g_body - fluid_.fluid.a_ext[b];
  buoyancy_ = generalised_buoyancy(n, pairs_, fluid_.mass, shepard_.s, a_pv, sphere_volume(p_.radius));
  const DiFeliceDrag dd{2.0 * p_.radius, fluid_.params.density, fluid_.params.viscosity};
  const StokesCoupledDrag st{p_.radius, fluid_.params.viscosity};
  u_at_ = shepard_.u;
  eps_at_ = shepard_.eps;
  coupling_.gamma.resize(n);
  coupling_.inv_mass.resize(n);
  coupling_.g.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = shepard_.s[i];
    // Collective inertia: the Shepard response of u_i to equal impulses of
    // all particles is -J sum_a (m/rho_a^2) W_ia Omega_a / s_i = -J/M_i
    // (exact for an isolated particle and for a uniform suspension).
    coupling_.inv_mass[i] = inv_m[i] / s;
    const double slip = (u_at_[i] - cell_.free.v[i]).norm();
    coupling_.gamma[i] = law_ == CoupledDrag::stokes ? drag_coefficient(st, slip, eps_at_[i])
                                                     : drag_coefficient(dd, slip, eps_at_[i]);
    // The parcel feels its fluid forces and the reaction of the buoyancy.
    coupling_.g[i] = acc[i] / s - coupling_.inv_mass[i] * buoyancy_[i];
  }
  parcel_.u = u_at_;
  std::fill(parcel_.impulse.begin(), parcel_.impulse.end(), Vec3::Zero());
}

void CoupledModel::update_dem_forces() {
  auto& f = cell_.free;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!f.x[i].allFinite() || !f.v[i].allFinite()) {
      std::ostringstream s;
      s << "non-finite " << (f.x[i].allFinite() ? "velocity" : "position") << " of particle " << i
        << " at DEM sub-step " << dem_steps() << " (fluid step " << steps_ << ", t = " << time_ << " s)";
      throw NumericalError(s.str());
    }
  wrap_all(f.x, cell_.box);
  wrap_all(cell_.walls.x, cell_.box);
  build_pair_lists(lists_, f, cell_.walls, cell_.box);  // rebuilds only the lists that may be stale
  const PairSums ps = compute_dem_forces(p_, cell_.box, f, cell_.walls, lists_, buffers_);
  sums_.dem.wall_fz[0] += ps.wall_fz[0];
  sums_.dem.wall_fz[1] += ps.wall_fz[1];
  sums_.dem.virial_mag_xz += ps.virial_mag_xz;
  sums_.dem.virial_con_xz += ps.virial_con_xz;
  sums_.dem.max_overlap = std::max(sums_.dem.max_overlap, ps.max_overlap);
  sums_.dem.energy_dipole = ps.energy_dipole;
  sums_.dem.energy_hertz = ps.energy_hertz;
  sums_.dem.pair_evaluations += ps.pair_evaluations;
  check_dem();
}

void CoupledModel::check_dem() const {
  const auto& f = cell_.free;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!f.f[i].allFinite()) {
      std::ostringstream s;
      s << "non-finite force on particle " << i << " at DEM sub-step " << dem_steps() << " (t = " << time_ << " s)";
      throw NumericalError(s.str());
    }
  if (sums_.dem.max_overlap > overlap_limit_) {
    std::ostringstream s;
    s << "contact stability limit exceeded at fluid step " << steps_ << " (t = " << time_
      << " s): overlap/R = " << sums_.dem.max_overlap / p_.radius << " > " << overlap_limit_ / p_.radius
      << ", the largest overlap the DEM sub-step " << dt_dem() << " s keeps stable; lower numerics.dt_safety";
    throw NumericalError(s.str());
  }
}

void CoupledModel::dem_substep() {
  auto& f = cell_.free;
  const double h = dt_dem();
  for (std::size_t i = 0; i < f.size(); ++i) f_old_[i] = f.f[i] + buoyancy_[i] + body_force_;
  const Vec3 dem_old = sum_of(f.f);
  parcel_advance(f.x, f.v, f_old_, coupling_, parcel_, p_.mass, h);
  move_walls(cell_.walls, p_.shear_rate, h);
  advance_pair_lists(lists_, p_.shear_rate * h);
  update_dem_forces();
  for (std::size_t i = 0; i < f.size(); ++i) f_new_[i] = f.f[i] + buoyancy_[i] + body_force_;
  parcel_correct(f.v, f_old_, f_new_, coupling_, parcel_, p_.mass, h);
  // Pair forces cancel: what is left of sum_i F_i is the walls' push.
  external_impulse_ += 0.5 * h * (dem_old + sum_of(f.f)) + (h * static_cast<double>(f.size())) * body_force_;
}

std::vector<Vec3> CoupledModel::fluid_acceleration(bool viscous, bool sample) {
  // Fluid forces of the current state (explicit SPH, REFERENCE §5).
  std::vector<Vec3> a = external_acceleration(fluid_);
  add_pressure_acceleration(fluid_, a);
  if (viscous) add_viscous_acceleration(fluid_, a);
  if (sample) {
    sums_.fluid_stress = wall_shear_stress(fluid_).tau;
    sums_.fluid_virial = -fluid_pair_virial_xz(fluid_) / fluid_.box.volume();
  }
  return a;
}

// The fluid receives minus the impulse the particles took from it (drag and
// buoyancy, N s), scattered with the Shepard weights (exact, §6), as a
// velocity kick per SPH particle; and the exchange virial of that force.
void CoupledModel::exchange_with_fluid(const std::vector<Vec3>& impulse, std::vector<Vec3>& kick, double dt) {
  kick.assign(fluid_.fluid.size(), Vec3::Zero());
  add_back_coupling(pairs_, impulse, shepard_.s, fluid_.fluid.rho, kick);
  double exchange_virial = 0.0;  // force on i from a: E_i/dt x scatter weight (m/rho_a) W_ia / s_i
  for (const CouplingPair& q : pairs_)
    exchange_virial += (cell_.free.x[q.i].x() - fluid_.fluid.x[q.a].x()) * impulse[q.i].z() *
                       (fluid_.mass * q.w / (fluid_.fluid.rho[q.a] * shepard_.s[q.i]));
  sums_.exchange_virial = -exchange_virial / (dt * fluid_.box.volume());
}

// The SPH particles over dt: v += dt a + kick (and the viscous term, or
// the viscous term and the pressure increment, by backward Euler where
// `implicit` says), x += dt v; the wall particles move with the walls. `a`
// holds the accelerations at the start.
void CoupledModel::advance_fluid(double dt, const std::vector<Vec3>& kick, std::vector<Vec3>& a,
                                 SphImplicit implicit) {
  const std::size_t nf = fluid_.fluid.size();
  Vec3 fluid_force = Vec3::Zero();
  for (std::size_t b = 0; b < nf; ++b) {
    fluid_.fluid.v[b] += dt * a[b] + kick[b];
    fluid_force += a[b];
  }
  external_impulse_ += (dt * fluid_.mass) * fluid_force;  // SPH pair terms cancel: walls + body force
  if (implicit != SphImplicit::none) {
    const ImplicitSolveStats st = solve_implicit_fluid(fluid_, dt, implicit, fluid_.fluid.v);
    viscous_iterations_ += st.iterations;
    // The walls' push at the new velocities, summed on its own: what the
    // fluid-fluid terms leave of the momentum change is the CG residual.
    external_impulse_ += fluid_.mass * st.wall_dv;
  }
  const double half = 0.5 * fluid_.box.gap;
  for (std::size_t b = 0; b < nf; ++b) {
    fluid_.fluid.x[b] += dt * fluid_.fluid.v[b];
    fluid_.box.wrap(fluid_.fluid.x[b]);
    Vec3& x = fluid_.fluid.x[b];
    if (std::abs(x.x()) >= half && std::abs(x.x()) < 2.0 * half) {
      // The SPH wall is soft (a pressure layer): at cell Reynolds numbers of
      // ~100 (Mn ~ 1) particles dragged by fast wall-bounced spheres can
      // still reach the plane. The wall is impermeable: reflect the particle
      // and give the wall the momentum 2 m v_x (counted, reported).
      const double side = x.x() > 0 ? 1.0 : -1.0;
      x.x() = 2.0 * side * half - x.x();
      external_impulse_.x() -= 2.0 * fluid_.mass * fluid_.fluid.v[b].x();
      fluid_.fluid.v[b].x() = -fluid_.fluid.v[b].x();
      ++sums_.wall_reflections;
    }
    if (!x.allFinite() || !fluid_.fluid.v[b].allFinite() || std::abs(x.x()) >= half) {
      std::ostringstream s;
      s << "SPH particle " << b << (x.allFinite() ? " crossed a wall plane" : " became non-finite")
        << " at step " << steps_ << " (t = " << time_ << " s): x = (" << x.transpose() << ") m, v = ("
        << fluid_.fluid.v[b].transpose() << ") m/s";
      throw NumericalError(s.str());
    }
  }
  for (std::size_t w = 0; w < fluid_.wall.size(); ++w) {
    fluid_.wall.x[w] += dt * fluid_.wall.v[w];
    fluid_.box.wrap(fluid_.wall.x[w]);
  }
}

void CoupledModel::step() {
  if (implicit_) return inertialess_step();
  const std::size_t n = cell_.free.size();
  std::vector<Vec3> a = fluid_acceleration(true, true);
  prepare_coupling(a);

  sums_.dem = PairSums{};
  f_old_.resize(n);
  f_new_.resize(n);
  for (int k = 0; k < substeps_; ++k) dem_substep();
  const double inv = 1.0 / substeps_;
  sums_.dem.wall_fz[0] *= inv;
  sums_.dem.wall_fz[1] *= inv;
  sums_.dem.virial_mag_xz *= inv;
  sums_.dem.virial_con_xz *= inv;

  std::vector<Vec3> exchange(n), kick;
  for (std::size_t i = 0; i < n; ++i) exchange[i] = parcel_.impulse[i] + dt_ * buoyancy_[i];
  exchange_with_fluid(exchange, kick, dt_);
  advance_fluid(dt_, kick, a, SphImplicit::none);
  time_ += dt_;
  fluid_.time = time_;
  ++steps_;
  fluid_.steps = steps_;
  sph_pairs_.strain += p_.shear_rate * dt_;
  refresh(fluid_, sph_pairs_);
  update_coupling_pairs();
  tally();
}

void CoupledModel::tally() {
  eps_seen_min_ = std::min(eps_seen_min_, sums_.eps_min);
  eps_seen_max_ = std::max(eps_seen_max_, sums_.eps_max);
  clamped_steps_ += sums_.eps_clamped > 0 ? 1 : 0;
}

}  // namespace mrf
