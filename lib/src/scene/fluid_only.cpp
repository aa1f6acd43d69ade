#include "mrf/scene/fluid_only.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/analytic.hpp"
#include "mrf/fluid/fluid_observables.hpp"

namespace mrf {

namespace {

void validate_scene(const SceneConfig& cfg, double t_end) {
  if (cfg.model == ModelId::dem_stokes)
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
  return viscous_limit(cell) < smallest(stability_limits(cell, true));
}

}  // namespace

FluidParams fluid_params_from_scene(const SceneConfig& cfg) {
  FluidParams p;
  p.viscosity = cfg.viscosity;
  p.density = cfg.fluid_density;
  p.spacing = cfg.sph_spacing;
  p.sound_speed = cfg.sound_speed;
  p.shear_rate = cfg.shear_rate;
  return p;
}

CouetteSphResult run_couette_sph(const SceneConfig& cfg, double t_end) {
  validate_scene(cfg, t_end);
  const Box box{cfg.gap, cfg.ly, cfg.lz};
  FluidCell cell = build_fluid_cell(box, fluid_params_from_scene(cfg));
  CouetteSphResult r;
  r.implicit_viscosity = use_implicit(cfg, cell);
  r.limits = stability_limits(cell, r.implicit_viscosity);
  double dt = cfg.dt_safety * smallest(r.limits);
  if (cfg.dt) {
    check_time_step(cell, *cfg.dt, r.implicit_viscosity);
    dt = *cfg.dt;
  }
  r.steps = static_cast<std::int64_t>(std::ceil(t_end / dt - 1e-9));
  r.dt = t_end / static_cast<double>(r.steps);
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t n = 0; n < r.steps; ++n) {
    if (r.implicit_viscosity)
      step_implicit(cell, r.dt);
    else
      step(cell, r.dt);
    r.max_density_deviation = std::max(r.max_density_deviation, density_stats(cell).max_abs_error);
  }
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const double L = box.gap, nu = cell.params.kinematic_viscosity(), V = 0.5 * cfg.shear_rate * L;
  r.time = cell.time;
  r.shear_stress = wall_shear_stress(cell).tau;
  r.analytic_stress = cfg.viscosity * couette_startup_shear_rate(0.0, r.time, L, nu, -V, V);
  r.steady_stress = cfg.viscosity * cfg.shear_rate;
  r.profile_error = profile_error(
      cell, [&](double x) { return couette_startup_velocity(x + 0.5 * L, r.time, L, nu, -V, V); });
  r.mean_density_error = density_stats(cell).mean_abs_error;
  r.reynolds = reynolds_number(cell.params, box);
  r.sound_speed = cell.c0;
  r.n_fluid = cell.fluid.size();
  r.n_wall = cell.wall.size();
  return r;
}

}  // namespace mrf
