#include "mrf/scene/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include "mrf/io/archive.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

RunSummary run_scene(const LoadedScene& scene, const RunOptions& opt) {
  const SceneConfig& c = scene.config;
  BuiltModel built = build_model(scene, opt.quiet);
  Model& model = *built.model;
  RunSummary s = std::move(built.summary);
  // Error-controlled steps run to the end time and write a row every `every`
  // steps of their largest dt, i.e. by strain interval; fixed steps write a
  // row every `every` steps.
  const bool adaptive = model.adaptive();
  const long every = series_every(scene, built.planned_steps);
  const long frame_every = c.frames > 0 ? std::max(1L, built.planned_steps / c.frames) : 0;
  RunFiles files(opt, c);
  LoopState st;
  const RunFiles::Start start = files.open(st, frame_every > 0, [&](ArchiveReader& in) { model.load(in); });
  if (start == RunFiles::Start::branched) {
    st.t_origin = st.row_start = model.time();
    RunSummary parent;  // the model's counts of work so far: the parent's, not this run's
    model.finish(parent);
    parent.neighbor_builds = model.lists().builds;
    st.work_before = work_counters(parent, model.lists().ff_builds);
  }
  // this run's strain: from its start (a branch's start is its parent's time)
  const auto run_strain = [&] { return (model.time() - st.t_origin) * c.shear_rate; };
  if (start == RunFiles::Start::resumed && !opt.quiet)
    std::fprintf(stderr, "  resuming from %s at step %ld (strain %.4g)\n", files.checkpoint().c_str(), st.n,
                 run_strain());
  if (start == RunFiles::Start::branched && !opt.quiet)
    std::fprintf(stderr, "  branching from %s at its strain %.4g\n", opt.branch_from.c_str(),
                 model.time() * c.shear_rate);
  const double t_end = st.t_origin + c.strain / c.shear_rate;
  model.set_stop_time(t_end);
  SeriesRow row;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_report = t0;
  const double row_time = static_cast<double>(every) * s.dt;  // adaptive: s.dt is the largest step
  const long structure_every = structure_stride(row_time * std::abs(c.shear_rate));
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
    const double strain = run_strain();
    st.max_overlap = std::max(st.max_overlap, row.max_overlap);
    if (files.series.is_open()) write_series_row(files.series, model.time() - st.t_origin, strain, row, c.radius);
    if ((st.row_start - st.t_origin) * c.shear_rate >= c.warmup_strain * (1 - 1e-12)) {  // whole rows after warm-up
      const bool structure = st.se.rows() % structure_every == 0;
      if (structure) row.clusters = cluster_stats(model.cell(), c.radius);
      st.se.push(row, structure);
    }
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
  const RunFiles::Elapsed elapsed = files.elapsed(st);
  s.wall_seconds = elapsed.wall;
  s.cpu_seconds = elapsed.cpu;
  s.steps = n;
  if (!opt.quiet) std::fprintf(stderr, "\r  done: %ld steps in %.1f s%40s\n", n, s.wall_seconds, "");
  st.se.finish(s);
  model.finish(s);  // after the series: a model may report its own stress (the fluid-only start-up)
  if (s.n_fluid > 0) s.extra["stress_fluid_err"] = st.se.fluid().err;
  s.extra["seconds_per_strain"] = s.wall_seconds / c.strain;
  s.max_overlap_over_radius = st.max_overlap / c.radius;
  s.neighbor_builds = model.lists().builds;
  // a branch counts its own work only
  const long ff_builds = subtract_work(st.work_before, s, model.lists().ff_builds);
  if (s.extra.count("implicit_newton_iterations"))
    s.extra["implicit_dt_mean"] = (model.time() - st.t_origin) / static_cast<double>(std::max(1L, n));
  // The Verlet skin at the end (chosen for cost unless numerics.skin is set)
  // and the steps per free-free build (neighbors/verlet_list.hpp).
  s.extra["neighbor_skin_over_radius"] = model.lists().skin / c.radius;
  s.extra["steps_per_pair_list_build"] = static_cast<double>(n) / static_cast<double>(std::max(1L, ff_builds));
  s.particle_steps_per_second = static_cast<double>(s.n_particles * s.steps) / s.wall_seconds;
  s.pair_evaluations_per_second = static_cast<double>(st.pair_evals) / s.wall_seconds;
  files.finish(s);
  return s;
}

}  // namespace mrf
