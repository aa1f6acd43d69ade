#include "mrf/scene/run_coupled.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/fluid/wcsph.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

namespace {

// Porosity the explicit viscous limit is designed for: the initial minimum,
// but no more than 0.5 (chains lower eps locally during a run; at phi = 0.3
// and a kernel of >= 2d the SPH-scale porosity stays above it).
constexpr double k_design_porosity = 0.5;

void print_start(const RunSummary& s, const CoupledTimeStep& t, const FluidCell& f) {
  std::fprintf(stderr, "mrf: %s, Mn = %.4g (9 eta gdot / 2 mu0 M^2), gdot = %.4g 1/s\n", s.model.c_str(), s.mason,
               s.shear_rate);
  std::fprintf(stderr, "  SPH: %zu fluid + %zu wall particles, dx = %.3g m, h = %.3g m, c0 = %.3g m/s\n",
               f.fluid.size(), f.wall.size(), f.params.spacing, f.h, f.c0);
  for (const auto& l : t.fluid_limits)
    std::fprintf(stderr, "  fluid       %-28s dt < %-10.3g  %s\n", l.name.c_str(), l.dt, l.basis.c_str());
  for (const auto& l : t.dem_limits)
    std::fprintf(stderr, "  DEM sub-step %-27s dt < %-10.3g  %s\n", l.name.c_str(), l.dt, l.basis.c_str());
  std::fprintf(stderr,
               "  chosen: fluid dt = %.4g s (%.3g tau_p) with %d DEM sub-steps of %.4g s; %ld fluid steps; "
               "St = %.3g, Re_p = %.3g\n",
               t.dt_fluid, t.dt_fluid / s.extra.at("tau_p"), t.substeps, t.dt_fluid / t.substeps,
               static_cast<long>(s.extra.at("fluid_steps")), s.stokes_number, s.reynolds_number);
}

}  // namespace

CoupledDrag coupled_drag(ModelId m) {
  return m == ModelId::demsph_dd ? CoupledDrag::di_felice : CoupledDrag::stokes;
}

CoupledTimeStep choose_coupled_time_step(const LoadedScene& scene, const DemParams& p, const FluidCell& fluid,
                                         double eps_min) {
  const SceneConfig& c = scene.config;
  if (c.integrator != IntegratorId::automatic && c.integrator != IntegratorId::verlet_exp)
    throw InputError("numerics.integrator", to_string(c.integrator), scene.locate("numerics.integrator"),
                     "the coupled models integrate the DEM with the exact-drag Verlet sub-step ('verlet_exp' "
                     "or 'auto')");
  CoupledTimeStep t;
  t.dem_limits = dem_limits(p, c, IntegratorId::verlet_exp);
  for (const SphStepLimit& l : stability_limits(fluid, false))
    if (!l.name.starts_with("viscous")) t.fluid_limits.push_back({l.name, l.dt, "Morris et al. 1997"});
  std::ostringstream basis;
  basis << "0.125 h^2 eps rho_f / eta, eps = " << eps_min << " (superficial density)";
  t.fluid_limits.push_back({"viscous (averaged)", coupled_viscous_limit(fluid, eps_min), basis.str()});
  const StabilityLimit& b = binding(t.fluid_limits);
  if (c.dt) {
    if (*c.dt > b.dt) {
      char value[32];
      std::snprintf(value, sizeof value, "%.6g s", *c.dt);
      throw InputError("numerics.dt", value, scene.locate("numerics.dt"),
                       "above the SPH stability limit '" + b.name + "' of the coupled fluid step");
    }
    t.dt_fluid = *c.dt;
  } else {
    t.dt_fluid = c.dt_safety * b.dt;
  }
  const double dem_dt = c.dt_safety * smallest(t.dem_limits);
  t.substeps = std::max(1, static_cast<int>(std::ceil(t.dt_fluid / dem_dt - 1e-9)));
  return t;
}

RunSummary run_coupled_scene(const LoadedScene& scene, const RunOptions& opt) {
  const SceneConfig& c = scene.config;
  if (c.threads > 0) omp_set_num_threads(c.threads);
  const DemParams p = dem_params(c);
  ShearCell cell = build_shear_cell(c, scene.locate("particles.volume_fraction"));
  for (std::size_t i = 0; i < cell.free.size(); ++i) cell.free.v[i] = couette_velocity(cell.free.x[i], c.shear_rate);
  FluidCell fluid = [&] {
    try {
      return build_coupled_fluid(c, cell);
    } catch (const InputError& e) {  // FluidParams::validate names the key; add the file line
      throw InputError(e.key(), "", scene.locate(e.key()), e.what());
    }
  }();
  const auto pairs0 = coupling_pairs(cell.free.x, fluid.fluid.x, cell.box, fluid.h);
  const auto eps0 = porosity_at_fluid(fluid.fluid.size(), sphere_volume(c.radius), pairs0).eps;
  const double eps_design = std::min(k_design_porosity, *std::min_element(eps0.begin(), eps0.end()));
  const CoupledTimeStep ts = choose_coupled_time_step(scene, p, fluid, eps_design);
  const long fluid_steps = static_cast<long>(std::ceil(c.strain / (c.shear_rate * ts.dt_fluid)));

  RunSummary s = scene_summary(c);
  s.integrator = "sph_explicit+dem_verlet_exp_parcel";
  s.binding_limit = binding(ts.fluid_limits).name;
  s.dt = ts.dt_fluid / ts.substeps;
  s.steps = fluid_steps * ts.substeps;
  s.n_particles = static_cast<long>(cell.free.size());
  s.n_wall = static_cast<long>(cell.walls.size());
  s.n_fluid = static_cast<long>(fluid.fluid.size());
  s.stokes_number = stokes_number(p);
  s.reynolds_number = particle_reynolds(c);
  s.extra = {{"dt_fluid", ts.dt_fluid},
             {"substeps", ts.substeps},
             {"fluid_steps", static_cast<double>(fluid_steps)},
             {"tau_p", p.tau_p},
             {"dt_fluid_over_tau_p", ts.dt_fluid / p.tau_p},
             {"sph_spacing", fluid.params.spacing},
             {"sph_h", fluid.h},
             {"sound_speed", fluid.c0},
             {"n_fluid_wall", static_cast<double>(fluid.wall.size())},
             {"cell_reynolds", reynolds_number(fluid.params, fluid.box)}};
  if (!opt.quiet) print_start(s, ts, fluid);

  CoupledModel model(std::move(cell), p, std::move(fluid), coupled_drag(c.model), ts.dt_fluid, ts.substeps);
  const Vec3 p0 = model.momentum();
  const long every = series_every(scene, fluid_steps);
  const long frame_every = c.frames > 0 ? std::max(1L, fluid_steps / c.frames) : 0;
  // What the coupled loop carries besides the LoopState (checkpointed with the model).
  struct {
    double eps_min = 1, eps_max = 0, momentum_scale = 0;
    long clamped_steps = 0;
  } cst;
  RunFiles files(opt, c);
  LoopState st;
  const bool resumed = files.open(st, frame_every > 0, [&](ArchiveReader& in) {
    in.get(cst);
    model.load(in);
  });
  if (resumed && !opt.quiet)
    std::fprintf(stderr, "  resuming from %s at fluid step %ld (strain %.4g)\n", files.checkpoint().c_str(), st.n,
                 model.time() * c.shear_rate);
  SeriesRow row;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  for (long n = st.n + 1; n <= fluid_steps; ++n) {
    model.step();
    const CoupledStepSums& cs = model.sums();
    row.add(cs.dem, model.cell().box, cs.fluid_stress, cs.fluid_virial + cs.exchange_virial);
    st.pair_evals += cs.dem.pair_evaluations;
    cst.eps_min = std::min(cst.eps_min, cs.eps_min);
    cst.eps_max = std::max(cst.eps_max, cs.eps_max);
    cst.clamped_steps += cs.eps_clamped > 0 ? 1 : 0;
    if (frame_every > 0 && n % frame_every == 0 && files.frames.is_open())
      write_frame(files.frames, model.cell(), p.radius, model.time());
    if (n % every != 0 && n != fluid_steps) continue;
    const double strain = model.time() * c.shear_rate;
    st.max_overlap = std::max(st.max_overlap, row.max_overlap);
    cst.momentum_scale =
        std::max(cst.momentum_scale, model.fluid().mass * static_cast<double>(model.fluid().fluid.size()) *
                                         std::abs(c.shear_rate) * 0.5 * model.cell().box.gap);
    if (files.series.is_open()) write_series_row(files.series, model.time(), strain, row, p.radius);
    if (strain - row.n * ts.dt_fluid * c.shear_rate >= c.warmup_strain) st.se.push(row);
    row = SeriesRow{};
    files.end_row(st, n, strain, n < fluid_steps, [&](ArchiveWriter& out) {
      out.put(cst);
      model.save(out);
    });
    const auto now = std::chrono::steady_clock::now();
    if (!opt.quiet && std::chrono::duration<double>(now - last_report).count() > 2.0) {
      last_report = now;
      const double el = std::chrono::duration<double>(now - t0).count();
      std::fprintf(stderr, "\r  strain %.3f / %.3f  %.3g DEM steps/s  eps %.3f-%.3f  ETA %.0f s   ", strain,
                   c.strain, static_cast<double>((n - st.n) * ts.substeps) / el, cs.eps_min, cs.eps_max,
                   el * static_cast<double>(fluid_steps - n) / static_cast<double>(n - st.n));
    }
  }
  s.wall_seconds = st.elapsed_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!opt.quiet)
    std::fprintf(stderr, "\r  done: %ld fluid steps x %d DEM sub-steps in %.1f s%30s\n", fluid_steps, ts.substeps,
                 s.wall_seconds, "");
  st.se.finish(s);
  const Vec3 drift = model.momentum() - p0 - model.external_impulse();
  s.max_overlap_over_radius = st.max_overlap / p.radius;
  s.neighbor_builds = model.lists().builds;
  s.particle_steps_per_second = static_cast<double>(s.n_particles * s.steps) / s.wall_seconds;
  s.pair_evaluations_per_second = static_cast<double>(st.pair_evals) / s.wall_seconds;
  s.extra["stress_fluid_err"] = st.se.fluid().err;
  s.extra["porosity_min"] = cst.eps_min;
  s.extra["porosity_max"] = cst.eps_max;
  s.extra["porosity_design"] = eps_design;
  s.extra["steps_with_clamped_porosity"] = static_cast<double>(cst.clamped_steps);
  s.extra["momentum_drift_N_s"] = drift.norm();
  s.extra["momentum_drift_relative"] = cst.momentum_scale > 0 ? drift.norm() / cst.momentum_scale : 0.0;
  s.extra["seconds_per_strain"] = s.wall_seconds / c.strain;
  s.extra["sph_wall_reflections"] = static_cast<double>(model.sums().wall_reflections);
  files.finish(s);
  return s;
}

}  // namespace mrf
