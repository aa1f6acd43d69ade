#include "mrf/scene/fluid_only.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/analytic.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {

namespace {

void validate_scene(const SceneConfig& cfg, double t_end) {
  if (is_one_way(cfg.model))
    throw InputError("scene.model", to_string(cfg.model), "", "the SPH Couette run needs an SPH model (demsph_*)");
  if (cfg.volume_fraction != 0.0) {
    std::ostringstream s;
    s << cfg.volume_fraction;
    throw InputError("particles.volume_fraction", s.str(), "", "must be 0 for the fluid-only Couette run");
  }
  if (!(t_end > 0) || !std::isfinite(t_end)) {
    std::ostringstream s;
    s << t_end;
    throw InputError("drive.strain", s.str(), "", "the simulated time strain / shear rate (s) must be positive");
  }
}

bool use_implicit(const SceneConfig& cfg, const FluidCell& cell) {
  if (cfg.integrator == IntegratorId::implicit) return true;
  if (cfg.integrator != IntegratorId::automatic) return false;
  return viscous_limit(cell) < smallest(stability_limits(cell, SphImplicit::viscosity));
}

}  // namespace

FluidParams fluid_params_from_scene(const SceneConfig& cfg) {
  FluidParams p;
  p.viscosity = cfg.viscosity;
  p.density = cfg.fluid_density;
  p.spacing = cfg.sph_spacing;
  p.sound_speed = cfg.sound_speed;
  p.shear_rate = cfg.shear_rate;
  p.common_eos_reference = cfg.eos_reference == EosReference::common;
  return p;
}

FluidOnlyChoice choose_fluid_only_step(const SceneConfig& cfg, const FluidCell& cell, double t_end) {
  validate_scene(cfg, t_end);
  FluidOnlyChoice c;
  c.implicit_viscosity = use_implicit(cfg, cell);
  c.limits = stability_limits(cell, c.implicit_viscosity ? SphImplicit::viscosity : SphImplicit::none);
  double dt = cfg.dt_safety * smallest(c.limits);
  if (cfg.dt) {
    check_time_step(cell, *cfg.dt, c.implicit_viscosity ? SphImplicit::viscosity : SphImplicit::none);
    dt = *cfg.dt;
  }
  c.steps = static_cast<long>(std::ceil(t_end / dt - 1e-9));
  c.dt = t_end / static_cast<double>(c.steps);
  return c;
}

FluidOnlyModel::FluidOnlyModel(FluidCell cell, bool implicit_viscosity, double dt)
    : fluid_(std::move(cell)), implicit_(implicit_viscosity), dt_(dt) {
  no_particles_.box = fluid_.box;
  stress_ = wall_shear_stress(fluid_).tau;
}

void FluidOnlyModel::step() {
  if (implicit_)
    step_implicit(fluid_, dt_);
  else
    mrf::step(fluid_, dt_);
  max_density_deviation_ = std::max(max_density_deviation_, density_stats(fluid_).max_abs_error);
  stress_ = wall_shear_stress(fluid_).tau;
}

StepSample FluidOnlyModel::sample() const { return {no_pairs_, stress_, 0.0, 1.0}; }

void FluidOnlyModel::load(ArchiveReader& in) {
  const std::size_t nf = fluid_.fluid.size(), nw = fluid_.wall.size();
  serialize(in, *this);
  if (fluid_.fluid.x.size() != nf || fluid_.fluid.v.size() != nf || fluid_.wall.x.size() != nw)
    throw NumericalError("checkpoint does not match the scene: SPH particle counts differ");
  refresh(fluid_);
  stress_ = wall_shear_stress(fluid_).tau;
}

void FluidOnlyModel::finish(RunSummary& s) const {
  const double L = fluid_.box.gap, nu = fluid_.params.kinematic_viscosity(), gdot = fluid_.params.shear_rate;
  const double V = 0.5 * gdot * L, t = fluid_.time;
  s.stress_total = {stress_, 0.0, 0.0};  // the value at the end: no averaging window in a start-up
  s.stress_fluid = stress_;
  // no volume-side stress is computed for the fluid alone (the series carry the wall stress only)
  for (const char* key : {"stress_virial_total", "stress_virial_total_err", "stress_virial_fluid", "stress_fluid_err",
                          "steady_mser_discard_fraction"})
    s.extra.erase(key);
  s.extra["stress_startup_series"] = fluid_.params.viscosity * couette_startup_shear_rate(0.0, t, L, nu, -V, V);
  s.extra["stress_steady_eta_gdot"] = fluid_.params.viscosity * gdot;
  s.extra["profile_error_l2"] = profile_error(
      fluid_, [&](double x) { return couette_startup_velocity(x + 0.5 * L, t, L, nu, -V, V); });
  s.extra["max_density_deviation"] = max_density_deviation_;
  s.extra["mean_density_error"] = density_stats(fluid_).mean_abs_error;
}

CouetteSphResult run_couette_sph(const SceneConfig& cfg, double t_end) {
  validate_scene(cfg, t_end);
  const Box box{cfg.gap, cfg.ly, cfg.lz};
  FluidCell cell = build_fluid_cell(box, fluid_params_from_scene(cfg));
  const FluidOnlyChoice choice = choose_fluid_only_step(cfg, cell, t_end);
  CouetteSphResult r;
  r.implicit_viscosity = choice.implicit_viscosity;
  r.limits = choice.limits;
  r.steps = choice.steps;
  r.dt = choice.dt;
  r.n_fluid = cell.fluid.size();
  r.n_wall = cell.wall.size();
  r.reynolds = reynolds_number(cell.params, box);
  r.sound_speed = cell.c0;
  FluidOnlyModel m(std::move(cell), choice.implicit_viscosity, choice.dt);
  const auto start = std::chrono::steady_clock::now();
  for (long n = 0; n < choice.steps; ++n) m.step();
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RunSummary s;
  m.finish(s);
  r.time = m.time();
  r.shear_stress = s.stress_total.mean;
  r.analytic_stress = s.extra.at("stress_startup_series");
  r.steady_stress = s.extra.at("stress_steady_eta_gdot");
  r.profile_error = s.extra.at("profile_error_l2");
  r.mean_density_error = s.extra.at("mean_density_error");
  r.max_density_deviation = m.max_density_deviation();
  return r;
}

}  // namespace mrf
