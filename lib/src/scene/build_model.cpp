#include "mrf/scene/build_model.hpp"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/fluid/wcsph.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/fluid_only.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

namespace {

// Porosity the explicit viscous limit is designed for: the initial minimum,
// but no more than 0.5 (chains lower eps locally during a run; at phi = 0.3
// and a kernel of >= 2d the SPH-scale porosity stays above it).
constexpr double k_design_porosity = 0.5;
// Verlet skin of the SPH pairs of the coupled schemes, / h. The pairs come
// sorted by (a, b, image) whenever the candidates were built, so the result
// does not depend on the rebuilds (a fresh search every step, as the inertial
// scheme did before session 25, orders them by cell: the sums round
// differently). An SPH particle's non-affine motion is a small fraction of h
// per step, so the list lasts tens of steps.
constexpr double k_sph_skin_over_h = 0.2;
// Verlet skin of the DEM-SPH coupling pairs, / h. It changes no result (the
// pairs equal a fresh search's); it trades the candidates' sweep,
// (1 + skin / 2h)^3 the pairs, against the rebuilds, about every
// skin / (3 (2h + skin)) of strain (the wall mirrors move with their
// particles, not with the flow at their place, so they spend the skin
// about twice as fast as the strain alone). 0.3 h: 1.5x the pairs, a
// rebuild every 0.04 strain at most (measured: reports/performance).
constexpr double k_coupling_skin_over_h = 0.3;

// An error-controlled step is at most this fraction of the averaging
// window (drive.strain - drive.warmup_strain), so that the window holds at
// least this many rows (one per step at most) for block averaging.
constexpr int k_window_steps = 64;

std::string g3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

void refuse_dt_above(const LoadedScene& scene, double dt, const StabilityLimit& b, const std::string& what) {
  char value[32];
  std::snprintf(value, sizeof value, "%.6g s", dt);
  throw InputError("numerics.dt", value, scene.locate("numerics.dt"),
                   "above the stability limit " + g3(b.dt) + " s of the " + what + ", set by '" + b.name + "' (" +
                       b.basis + ")");
}

void print_table(const char* label, const std::vector<StabilityLimit>& limits) {
  for (const auto& x : limits)
    std::fprintf(stderr, "  %-13s %-22s dt < %-10.3g  %s\n", label, x.name.c_str(), x.dt, x.basis.c_str());
}

}  // namespace

StabilityLimit window_limit(const SceneConfig& c) {
  const double window = c.strain - c.warmup_strain;
  const double dt = c.shear_rate != 0 && window > 0 ? window / (k_window_steps * std::abs(c.shear_rate))
                                                    : std::numeric_limits<double>::infinity();
  return {"averaging window", dt,
          "at least " + std::to_string(k_window_steps) + " steps in drive.strain - drive.warmup_strain"};
}

TimeStepChoice choose_time_step(const LoadedScene& scene, const DemParams& p) {
  const SceneConfig& c = scene.config;
  auto ve = dem_limits(p, c.gap, IntegratorId::verlet_exp);
  auto od = dem_limits(p, c.gap, IntegratorId::overdamped);
  auto im = dem_limits(p, c.gap, IntegratorId::implicit);
  TimeStepChoice t{};
  t.scheme = c.integrator == IntegratorId::automatic ? auto_integrator(ve, od, im, stokes_number(p)) : c.integrator;
  switch (t.scheme) {
    case IntegratorId::verlet_exp: t.limits = ve, t.other = od; break;
    case IntegratorId::overdamped: t.limits = od, t.other = ve; break;
    default:
      t.limits = im, t.other = smallest(ve) >= smallest(od) ? ve : od;
      t.limits.push_back(window_limit(c));
      break;
  }
  const StabilityLimit& b = binding(t.limits);
  if (c.dt) {
    if (*c.dt > b.dt) refuse_dt_above(scene, *c.dt, b, std::string(to_string(t.scheme)) + " integrator");
    t.dt = *c.dt;
  } else {
    // implicit: the bound is the largest step of an error-controlled scheme, not a stability limit
    t.dt = t.scheme == IntegratorId::implicit ? b.dt : c.dt_safety * b.dt;
  }
  return t;
}

CoupledDrag coupled_drag(ModelId m) {
  return m == ModelId::demsph_dd ? CoupledDrag::di_felice : CoupledDrag::stokes;
}

CoupledTimeStep choose_coupled_time_step(const LoadedScene& scene, const DemParams& p, const FluidCell& fluid,
                                         double eps_min) {
  const SceneConfig& c = scene.config;
  if (c.integrator == IntegratorId::overdamped)
    throw InputError("numerics.integrator", to_string(c.integrator), scene.locate("numerics.integrator"),
                     "the coupled models integrate the particles with inertia ('verlet_exp') or inertialess with "
                     "implicit contacts ('implicit'), or choose by the Stokes number ('auto')");
  const bool inertialess = c.integrator == IntegratorId::implicit ||
                           (c.integrator == IntegratorId::automatic && stokes_number(p) <= k_inertialess_max_stokes);
  CoupledTimeStep t;
  CoupledStepping& s = t.stepping;
  s.scheme = inertialess ? CoupledScheme::inertialess : CoupledScheme::inertial;
  // The SPH step: CFL (and force), and the viscous bound of the averaged
  // equations, 0.125 h^2 eps rho_f / eta (the superficial density carries
  // the momentum), unless the viscosity is implicit. Inertialess, where the
  // acoustic CFL step is shorter than the particles' largest step, sound is
  // implicit too: one SPH step per particle step instead of several.
  t.fluid_limits = stability_limits(fluid, SphImplicit::viscosity);
  const double viscous = coupled_viscous_limit(fluid, eps_min);
  t.dem_limits = dem_limits(p, c.gap, inertialess ? IntegratorId::implicit : IntegratorId::verlet_exp);
  if (inertialess) t.dem_limits.push_back(window_limit(c));
  if (inertialess && c.dt_safety * smallest(t.fluid_limits) < (c.dt ? *c.dt : smallest(t.dem_limits))) {
    s.sph = SphImplicit::pressure_viscosity;
    t.fluid_limits = stability_limits(fluid, s.sph);
  } else if (inertialess && k_implicit_viscosity_gain * viscous < smallest(t.fluid_limits)) {
    s.sph = SphImplicit::viscosity;
  } else {
    t.fluid_limits.push_back({"viscous (averaged)", viscous,
                              "0.125 h^2 eps rho_f / eta, eps = " + g3(eps_min) + " (superficial density)"});
  }
  const StabilityLimit& bf = binding(t.fluid_limits);
  s.coupling_skin = k_coupling_skin_over_h * fluid.h;
  s.sph_skin = k_sph_skin_over_h * fluid.h;
  if (inertialess) {
    const StabilityLimit& bd = binding(t.dem_limits);
    if (c.dt && *c.dt > bd.dt) refuse_dt_above(scene, *c.dt, bd, "implicit coupled step");
    s.dt_max = c.dt ? *c.dt : bd.dt;
    s.dt_fluid = c.dt_safety * bf.dt;
    s.implicit.tol_over_radius = c.implicit_tol;
    s.implicit.newton_tol_over_radius = c.newton_tol;
    s.implicit.order = c.implicit_order;
    return t;
  }
  if (c.dt && *c.dt > bf.dt) refuse_dt_above(scene, *c.dt, bf, "SPH step of the coupled models");
  s.dt_fluid = c.dt ? *c.dt : c.dt_safety * bf.dt;
  const double dem_dt = c.dt_safety * smallest(t.dem_limits);
  s.substeps = std::max(1, static_cast<int>(std::ceil(s.dt_fluid / dem_dt - 1e-9)));
  return t;
}

namespace {

BuiltModel build_dem(const LoadedScene& scene, ShearCell cell, const DemParams& p, bool quiet) {
  const SceneConfig& c = scene.config;
  const TimeStepChoice ts = choose_time_step(scene, p);
  BuiltModel b;
  RunSummary& s = b.summary;
  s = scene_summary(c);
  s.integrator = to_string(ts.scheme);
  s.binding_limit = binding(ts.limits).name;
  s.dt = ts.dt;
  b.planned_steps = static_cast<long>(std::ceil(c.strain / (c.shear_rate * ts.dt)));
  s.steps = b.planned_steps;
  s.n_particles = static_cast<long>(cell.free.size());
  s.n_wall = static_cast<long>(cell.walls.size());
  s.stokes_number = stokes_number(p);
  s.reynolds_number = particle_reynolds(c);
  s.stress_fluid = imposed_fluid_stress(c.viscosity, c.shear_rate);
  if (!quiet) {
    std::fprintf(stderr, "mrf: %s, Mn = %.4g (9 eta gdot / 2 mu0 M^2), gdot = %.4g 1/s\n", s.model.c_str(), s.mason,
                 s.shear_rate);
    for (IntegratorId id : {IntegratorId::verlet_exp, IntegratorId::overdamped, IntegratorId::implicit}) {
      const auto l = dem_limits(p, c.gap, id);
      print_table(to_string(id), l);
      std::fprintf(stderr, "  %-13s bound by '%s' (dt < %.3g s)\n", to_string(id), binding(l).name.c_str(),
                   smallest(l));
    }
    std::fprintf(stderr, "  chosen: %s, %s dt %s %.4g s (bound by '%s'); St = %.3g (inertialess up to %.3g), "
                 "Re_p = %.3g\n",
                 s.integrator.c_str(), ts.scheme == IntegratorId::implicit ? "error-controlled" : "fixed",
                 ts.scheme == IntegratorId::implicit ? "<=" : "=", ts.dt, s.binding_limit.c_str(), s.stokes_number,
                 k_inertialess_max_stokes, s.reynolds_number);
  }
  auto model = std::make_unique<DemModel>(std::move(cell), p, ts.scheme, ts.dt);
  ImplicitOptions o;
  o.tol_over_radius = c.implicit_tol;
  o.newton_tol_over_radius = c.newton_tol;
  o.order = c.implicit_order;
  if (ts.scheme == IntegratorId::implicit) model->set_implicit_options(o);
  b.model = std::move(model);
  return b;
}

BuiltModel build_coupled(const LoadedScene& scene, ShearCell cell, const DemParams& p, bool quiet) {
  const SceneConfig& c = scene.config;
  FluidCell fluid = [&] {
    try {
      return build_coupled_fluid(c, cell);
    } catch (const InputError& e) {  // FluidParams::validate names the key; the scene knows its line
      throw e.at(scene.locate(e.key()));
    }
  }();
  const auto pairs0 = coupling_pairs(cell.free.x, fluid.fluid.x, cell.box, fluid.h);
  const auto eps0 = porosity_at_fluid(fluid.fluid.size(), sphere_volume(c.radius), pairs0).eps;
  const double eps_design = std::min(k_design_porosity, *std::min_element(eps0.begin(), eps0.end()));
  const CoupledTimeStep ts = choose_coupled_time_step(scene, p, fluid, eps_design);
  const CoupledStepping& st = ts.stepping;
  const bool inertialess = st.scheme == CoupledScheme::inertialess;
  BuiltModel b;
  RunSummary& s = b.summary;
  s = scene_summary(c);
  const double dt_dem = inertialess ? st.dt_max : st.dt_fluid / st.substeps;
  s.integrator = inertialess ? std::string("inertialess_implicit+sph_") + to_string(st.sph)
                             : "sph_explicit+dem_verlet_exp_parcel";
  s.binding_limit = inertialess ? binding(ts.dem_limits).name : binding(ts.fluid_limits).name;
  s.dt = dt_dem;
  b.planned_steps = static_cast<long>(std::ceil(c.strain / (c.shear_rate * (inertialess ? st.dt_max : st.dt_fluid))));
  s.steps = inertialess ? b.planned_steps : b.planned_steps * st.substeps;
  s.n_particles = static_cast<long>(cell.free.size());
  s.n_wall = static_cast<long>(cell.walls.size());
  s.n_fluid = static_cast<long>(fluid.fluid.size());
  s.stokes_number = stokes_number(p);
  s.reynolds_number = particle_reynolds(c);
  s.extra = {{"dt_fluid", st.dt_fluid},
             {"tau_p", p.tau_p},
             {"dt_fluid_over_tau_p", st.dt_fluid / p.tau_p},
             {"sph_spacing", fluid.params.spacing},
             {"sph_h", fluid.h},
             {"sound_speed", fluid.c0},
             {"n_fluid_wall", static_cast<double>(fluid.wall.size())},
             {"cell_reynolds", reynolds_number(fluid.params, fluid.box)},
             {"porosity_design", eps_design}};
  if (!inertialess) s.extra["substeps"] = st.substeps;
  if (!quiet) {
    std::fprintf(stderr, "mrf: %s, Mn = %.4g (9 eta gdot / 2 mu0 M^2), gdot = %.4g 1/s\n", s.model.c_str(), s.mason,
                 s.shear_rate);
    std::fprintf(stderr, "  SPH: %zu fluid + %zu wall particles, dx = %.3g m, h = %.3g m, c0 = %.3g m/s\n",
                 fluid.fluid.size(), fluid.wall.size(), fluid.params.spacing, fluid.h, fluid.c0);
    print_table("fluid", ts.fluid_limits);
    print_table(inertialess ? "particles" : "DEM sub-step", ts.dem_limits);
    if (inertialess)
      std::fprintf(stderr,
                   "  chosen: inertialess particles (St = %.3g <= %.3g), implicit contacts, error-controlled dt <= "
                   "%.4g s (bound by '%s'); SPH sub-steps <= %.4g s, %s; Re_p = %.3g\n",
                   s.stokes_number, k_inertialess_max_stokes, st.dt_max, s.binding_limit.c_str(), st.dt_fluid,
                   st.sph == SphImplicit::pressure_viscosity ? "sound and viscosity implicit"
                   : st.sph == SphImplicit::viscosity        ? "viscosity implicit"
                                                             : "explicit",
                   s.reynolds_number);
    else
      std::fprintf(stderr,
                   "  chosen: inertial particles (St = %.3g), fluid dt = %.4g s (%.3g tau_p) with %d DEM sub-steps "
                   "of %.4g s; Re_p = %.3g\n",
                   s.stokes_number, st.dt_fluid, st.dt_fluid / p.tau_p, st.substeps, dt_dem, s.reynolds_number);
  }
  b.model = std::make_unique<CoupledModel>(std::move(cell), p, std::move(fluid), coupled_drag(c.model), st);
  return b;
}

BuiltModel build_fluid_only(const LoadedScene& scene, bool quiet) {
  const SceneConfig& c = scene.config;
  const double t_end = c.strain / c.shear_rate;
  FluidCell fluid = build_fluid_cell(Box{c.gap, c.ly, c.lz}, fluid_params_from_scene(c));
  const FluidOnlyChoice ch = choose_fluid_only_step(c, fluid, t_end);
  BuiltModel b;
  RunSummary& s = b.summary;
  s = scene_summary(c);
  s.integrator = ch.implicit_viscosity ? "sph_implicit_viscosity" : "sph_explicit";
  s.binding_limit = binding(ch.limits).name;
  s.dt = ch.dt;
  b.planned_steps = ch.steps;
  s.steps = ch.steps;
  s.n_fluid = static_cast<long>(fluid.fluid.size());
  s.reynolds_number = reynolds_number(fluid.params, fluid.box);
  s.extra = {{"sound_speed", fluid.c0}, {"n_fluid_wall", static_cast<double>(fluid.wall.size())}};
  if (!quiet) {
    std::fprintf(stderr, "mrf: fluid-only SPH shear cell, gdot = %.4g 1/s, %zu fluid particles\n", c.shear_rate,
                 fluid.fluid.size());
    print_table("fluid", ch.limits);
    std::fprintf(stderr, "  chosen: %s, dt = %.4g s, %ld steps, Re = %.3g\n", s.integrator.c_str(), ch.dt, ch.steps,
                 s.reynolds_number);
  }
  b.model = std::make_unique<FluidOnlyModel>(std::move(fluid), ch.implicit_viscosity, ch.dt);
  return b;
}

}  // namespace

BuiltModel build_model(const LoadedScene& scene, bool quiet) {
  const SceneConfig& c = scene.config;
  use_scene_threads(c);
  if (!is_one_way(c.model) && c.volume_fraction == 0) return build_fluid_only(scene, quiet);
  const DemParams p = dem_params(c);
  ShearCell cell = build_shear_cell(c, scene.locate("particles.volume_fraction"));
  for (std::size_t i = 0; i < cell.free.size(); ++i) cell.free.v[i] = couette_velocity(cell.free.x[i], c.shear_rate);
  BuiltModel b = is_one_way(c.model) ? build_dem(scene, std::move(cell), p, quiet)
                                     : build_coupled(scene, std::move(cell), p, quiet);
  b.summary.extra.insert({{"dipole_cutoff", c.dipole_cutoff}, {"gap", c.gap}, {"radius", c.radius}, {"box_ly", c.ly}, {"box_lz", c.lz}});
  return b;
}

}  // namespace mrf
