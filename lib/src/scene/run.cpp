#include "mrf/scene/run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "mrf/io/archive.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/fluid_only.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

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
  if (c.model != ModelId::dem_stokes && c.volume_fraction == 0) return run_fluid_only(scene, opt);
  BuiltModel built = build_model(scene, opt.quiet);
  Model& model = *built.model;
  RunSummary s = std::move(built.summary);
  // Error-controlled steps run to the end time and write a row every `every`
  // steps of their largest dt, i.e. by strain interval; fixed steps write a
  // row every `every` steps.
  const bool adaptive = model.adaptive();
  const double t_end = c.strain / c.shear_rate;
  model.set_stop_time(t_end);
  const long every = series_every(scene, built.planned_steps);
  const long frame_every = c.frames > 0 ? std::max(1L, built.planned_steps / c.frames) : 0;
  RunFiles files(opt, c);
  LoopState st;
  if (files.open(st, frame_every > 0, [&](ArchiveReader& in) { model.load(in); }) && !opt.quiet)
    std::fprintf(stderr, "  resuming from %s at step %ld (strain %.4g)\n", files.checkpoint().c_str(), st.n,
                 model.time() * c.shear_rate);
  SeriesRow row;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  const double row_time = static_cast<double>(every) * s.dt;  // adaptive: s.dt is the largest step
  long n = st.n;
  auto running = [&] { return adaptive ? model.time() < t_end * (1 - 1e-12) : n < built.planned_steps; };
  while (running()) {
    ++n;
    model.step();
    const StepSample smp = model.sample();
    row.add(smp.dem, model.cell().box, smp.fluid_stress, smp.fluid_virial, smp.weight);
    st.pair_evals += smp.dem.pair_evaluations;
    if (frame_every > 0 && n % frame_every == 0 && files.frames.is_open())
      write_frame(files.frames, model.cell(), c.radius, model.time());
    const bool row_due = adaptive ? model.time() >= st.row_start + row_time * (1 - 1e-9) : n % every == 0;
    if (!row_due && running()) continue;
    const double strain = model.time() * c.shear_rate;
    st.max_overlap = std::max(st.max_overlap, row.max_overlap);
    if (files.series.is_open()) write_series_row(files.series, model.time(), strain, row, c.radius);
    if (st.row_start * c.shear_rate >= c.warmup_strain * (1 - 1e-12)) st.se.push(row);  // whole rows after warm-up
    row = SeriesRow{};
    st.row_start = model.time();
    files.end_row(st, n, strain, running(), [&](ArchiveWriter& out) { model.save(out); });
    const auto now = std::chrono::steady_clock::now();
    if (!opt.quiet && std::chrono::duration<double>(now - last_report).count() > 2.0) {
      last_report = now;
      const double el = std::chrono::duration<double>(now - t0).count();
      std::fprintf(stderr, "\r  strain %.3f / %.3f  %.3g steps/s  %s  ETA %.0f s   ", strain, c.strain,
                   static_cast<double>(n - st.n) / el, model.progress().c_str(),
                   el * (c.strain - strain) / (strain - st.strain_before));
    }
  }
  s.wall_seconds = st.elapsed_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.steps = n;
  model.finish(s);
  if (!opt.quiet) std::fprintf(stderr, "\r  done: %ld steps in %.1f s%40s\n", n, s.wall_seconds, "");
  st.se.finish(s);
  if (s.n_fluid > 0) s.extra["stress_fluid_err"] = st.se.fluid().err;
  s.extra["seconds_per_strain"] = s.wall_seconds / c.strain;
  s.max_overlap_over_radius = st.max_overlap / c.radius;
  s.neighbor_builds = model.lists().builds;
  s.particle_steps_per_second = static_cast<double>(s.n_particles * s.steps) / s.wall_seconds;
  s.pair_evaluations_per_second = static_cast<double>(st.pair_evals) / s.wall_seconds;
  files.finish(s);
  return s;
}

}  // namespace mrf
