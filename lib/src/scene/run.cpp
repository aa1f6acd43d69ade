#include "mrf/scene/run.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/couette_sph.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/run_coupled.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

TimeStepChoice choose_time_step(const LoadedScene& scene, const DemParams& p) {
  const SceneConfig& c = scene.config;
  auto ve = dem_limits(p, c, IntegratorId::verlet_exp);
  auto od = dem_limits(p, c, IntegratorId::overdamped);
  auto im = dem_limits(p, c, IntegratorId::implicit);
  TimeStepChoice t{};
  t.scheme = c.integrator == IntegratorId::automatic ? auto_integrator(ve, od, im) : c.integrator;
  switch (t.scheme) {
    case IntegratorId::verlet_exp: t.limits = ve, t.other = od; break;
    case IntegratorId::overdamped: t.limits = od, t.other = ve; break;
    default: t.limits = im, t.other = smallest(ve) >= smallest(od) ? ve : od; break;
  }
  const StabilityLimit& b = binding(t.limits);
  if (c.dt) {
    if (*c.dt > b.dt) {
      std::ostringstream why;
      why << "above the stability limit " << b.dt << " s of the " << to_string(t.scheme)
          << " integrator, set by '" << b.name << "' (" << b.basis << ")";
      char value[32];
      std::snprintf(value, sizeof value, "%.6g s", *c.dt);
      throw InputError("numerics.dt", value, scene.locate("numerics.dt"), why.str());
    }
    t.dt = *c.dt;
  } else {
    // implicit: the bound is the largest step of an error-controlled scheme, not a stability limit
    t.dt = t.scheme == IntegratorId::implicit ? b.dt : c.dt_safety * b.dt;
  }
  return t;
}

namespace {

// The limits of every DEM integrator, the one that binds each, and the choice.
void print_limits(const TimeStepChoice& t, const RunSummary& s, const DemParams& p, const SceneConfig& c) {
  std::fprintf(stderr, "mrf: %s, Mn = %.4g (9 eta gdot / 2 mu0 M^2), gdot = %.4g 1/s\n",
               s.model.c_str(), s.mason, s.shear_rate);
  for (IntegratorId id : {IntegratorId::verlet_exp, IntegratorId::overdamped, IntegratorId::implicit}) {
    const auto l = dem_limits(p, c, id);
    for (const auto& x : l)
      std::fprintf(stderr, "  %-11s %-20s dt < %-10.3g  %s\n", to_string(id), x.name.c_str(), x.dt, x.basis.c_str());
    std::fprintf(stderr, "  %-11s bound by '%s' (dt < %.3g s)\n", to_string(id), binding(l).name.c_str(), smallest(l));
  }
  if (t.scheme == IntegratorId::implicit)
    std::fprintf(stderr, "  chosen: implicit, error-controlled dt <= %.4g s (bound by '%s'); St = %.3g, Re_p = %.3g\n",
                 t.dt, binding(t.limits).name.c_str(), s.stokes_number, s.reynolds_number);
  else
    std::fprintf(stderr, "  chosen: %s, dt = %.4g s (bound by '%s'), %ld steps; St = %.3g, Re_p = %.3g\n",
                 to_string(t.scheme), t.dt, binding(t.limits).name.c_str(), s.steps, s.stokes_number,
                 s.reynolds_number);
}

}  // namespace

// Everything summary.json states about a DEM run before it starts.
static RunSummary dem_summary_header(const SceneConfig& c, const DemParams& p, const TimeStepChoice& ts,
                                     const ShearCell& cell) {
  RunSummary s = scene_summary(c);
  s.integrator = to_string(ts.scheme);
  s.binding_limit = binding(ts.limits).name;
  s.dt = ts.dt;
  s.steps = static_cast<long>(std::ceil(c.strain / (c.shear_rate * ts.dt)));
  s.n_particles = static_cast<long>(cell.free.size());
  s.n_wall = static_cast<long>(cell.walls.size());
  s.stokes_number = stokes_number(p);
  s.reynolds_number = particle_reynolds(c);
  s.stress_fluid = imposed_fluid_stress(c.viscosity, c.shear_rate);
  return s;
}

// A fluid-only SPH shear cell (model demsph_*, no particles): start-up
// Couette flow to the requested strain; the stress is the wall stress at the
// end, with the start-up series beside it (no averaging window: one value).
static RunSummary run_fluid_only(const LoadedScene& scene, const RunOptions& opt) {
  const SceneConfig& c = scene.config;
  const CouetteSphResult r = run_couette_sph(c, c.strain / c.shear_rate);
  RunSummary s = scene_summary(c);
  s.integrator = r.implicit_viscosity ? "sph_implicit_viscosity" : "sph_explicit";
  s.dt = r.dt;
  s.steps = r.steps;
  s.n_fluid = static_cast<long>(r.n_fluid);
  s.stress_total = {r.shear_stress, 0.0, 0.0};
  s.stress_fluid = r.shear_stress;
  s.reynolds_number = r.reynolds;
  s.wall_seconds = r.wall_seconds;
  s.extra = {{"stress_startup_series", r.analytic_stress},
             {"stress_steady_eta_gdot", r.steady_stress},
             {"profile_error_l2", r.profile_error},
             {"max_density_deviation", r.max_density_deviation},
             {"sound_speed", r.sound_speed},
             {"n_fluid_wall", static_cast<double>(r.n_wall)}};
  if (!opt.quiet) {
    std::fprintf(stderr, "mrf: fluid-only SPH shear cell, gdot = %.4g 1/s, %zu fluid particles\n",
                 c.shear_rate, r.n_fluid);
    for (const auto& l : r.limits) std::fprintf(stderr, "  %-24s dt < %.3g\n", l.name.c_str(), l.dt);
    std::fprintf(stderr, "  chosen: %s, dt = %.4g s, %lld steps, Re = %.3g\n", s.integrator.c_str(), r.dt,
                 static_cast<long long>(r.steps), r.reynolds);
  }
  if (!opt.out_dir.empty()) {
    std::filesystem::create_directories(opt.out_dir);
    std::ofstream ts(opt.out_dir + "/timeseries.csv");
    ts.precision(10);
    ts << "time_s,strain,stress_total_Pa,stress_startup_series_Pa,profile_error_l2\n"
       << r.time << "," << r.time * c.shear_rate << "," << r.shear_stress << "," << r.analytic_stress
       << "," << r.profile_error << "\n";
    write_file_atomic(opt.out_dir + "/summary.json", summary_json(s) + "\n");
  }
  return s;
}

RunSummary run_scene(const LoadedScene& scene, const RunOptions& opt) {
  const SceneConfig& c = scene.config;
  if (c.model != ModelId::dem_stokes) {
    if (c.volume_fraction == 0) return run_fluid_only(scene, opt);
    return run_coupled_scene(scene, opt);
  }
  if (c.threads > 0) omp_set_num_threads(c.threads);
  const DemParams p = dem_params(c);
  const TimeStepChoice ts = choose_time_step(scene, p);
  ShearCell cell = build_shear_cell(c, scene.locate("particles.volume_fraction"));
  for (std::size_t i = 0; i < cell.free.size(); ++i) cell.free.v[i] = couette_velocity(cell.free.x[i], c.shear_rate);

  RunSummary s = dem_summary_header(c, p, ts, cell);
  s.extra.insert({{"dipole_cutoff", c.dipole_cutoff}, {"gap", c.gap}, {"box_ly", c.ly}, {"box_lz", c.lz}});
  if (!opt.quiet) print_limits(ts, s, p, c);

  DemModel model(std::move(cell), p, ts.scheme, ts.dt);
  ImplicitOptions implicit_opt;
  implicit_opt.tol_over_radius = c.implicit_tol;
  implicit_opt.order = c.implicit_order;
  model.set_implicit_options(implicit_opt);
  // The implicit scheme chooses its steps: it runs to the end time and writes
  // a row every `every` steps of its largest dt, i.e. by strain interval.
  const bool adaptive = ts.scheme == IntegratorId::implicit;
  const double t_end = c.strain / c.shear_rate;
  if (adaptive) model.set_stop_time(t_end);
  const long every = series_every(scene, s.steps);
  const long frame_every = c.frames > 0 ? std::max(1L, s.steps / c.frames) : 0;
  RunFiles files(opt, c);
  LoopState st;
  if (files.open(st, frame_every > 0, [&](ArchiveReader& in) { model.load(in); }) && !opt.quiet)
    std::fprintf(stderr, "  resuming from %s at step %ld (strain %.4g)\n", files.checkpoint().c_str(), st.n,
                 model.time() * c.shear_rate);
  SeriesRow row;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  const double row_time = static_cast<double>(every) * ts.dt;
  long n = st.n;
  auto running = [&] { return adaptive ? model.time() < t_end * (1 - 1e-12) : n < s.steps; };
  while (running()) {
    ++n;
    model.step();
    row.add(model.sums(), model.cell().box, s.stress_fluid, s.stress_fluid, adaptive ? model.dt() : 1.0);
    st.pair_evals += model.sums().pair_evaluations;
    if (frame_every > 0 && n % frame_every == 0 && files.frames.is_open())
      write_frame(files.frames, model.cell(), p.radius, model.time());
    const bool row_due = adaptive ? model.time() >= st.row_start + row_time * (1 - 1e-9) : n % every == 0;
    if (!row_due && running()) continue;
    const double strain = model.time() * c.shear_rate;
    st.max_overlap = std::max(st.max_overlap, row.max_overlap);
    if (files.series.is_open()) write_series_row(files.series, model.time(), strain, row, p.radius);
    if ((adaptive ? st.row_start * c.shear_rate : strain - row.n * ts.dt * c.shear_rate) >= c.warmup_strain)
      st.se.push(row);  // whole row after warm-up
    row = SeriesRow{};
    st.row_start = model.time();
    files.end_row(st, n, strain, running(), [&](ArchiveWriter& out) { model.save(out); });
    const auto now = std::chrono::steady_clock::now();
    if (!opt.quiet && std::chrono::duration<double>(now - last_report).count() > 2.0) {
      last_report = now;
      const double el = std::chrono::duration<double>(now - t0).count();
      const double done_strain = strain - st.strain_before;
      std::fprintf(stderr, "\r  strain %.3f / %.3f  %.3g steps/s  ETA %.0f s   ", strain, c.strain,
                   static_cast<double>(n - st.n) / el, el * (c.strain - strain) / done_strain);
    }
  }
  s.wall_seconds = st.elapsed_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.steps = n;
  if (adaptive) {
    const ImplicitCounters& ic = model.implicit_counters();
    s.extra["implicit_rejected_steps"] = static_cast<double>(ic.rejected);
    s.extra["implicit_newton_failures"] = static_cast<double>(ic.newton_failures);
    s.extra["implicit_newton_iterations"] = static_cast<double>(ic.newton_iterations);
    s.extra["implicit_linear_iterations"] = static_cast<double>(ic.linear_iterations);
    s.extra["implicit_dt_min"] = ic.dt_min;
    s.extra["implicit_dt_max"] = ic.dt_max;
    s.extra["implicit_dt_mean"] = t_end / static_cast<double>(n);
  }
  if (!opt.quiet) std::fprintf(stderr, "\r  done: %ld steps in %.1f s%30s\n", s.steps, s.wall_seconds, "");
  st.se.finish(s);
  s.max_overlap_over_radius = st.max_overlap / p.radius;
  s.neighbor_builds = model.lists().builds;
  s.particle_steps_per_second = static_cast<double>(s.n_particles * s.steps) / s.wall_seconds;
  s.pair_evaluations_per_second = static_cast<double>(st.pair_evals) / s.wall_seconds;
  files.finish(s);
  return s;
}

}  // namespace mrf
