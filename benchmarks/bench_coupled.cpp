// One step of each model on the paper scene (gap 150 um, 50 x 120 um, phi
// 0.30, dipole cutoff 4 d; SPH dx = 10 um, h = 13 um for the coupled models),
// built by build_model as `mrf run` builds them, side by side in one run.
// The counter s_per_strain = time per step / (mean dt gdot) compares the
// models and schemes per strain unit: model 1 and the coupled models at
// `auto` (inertialess, implicit contacts), and the coupled models with the
// inertial multi-rate scheme (numerics.integrator = verlet_exp: one SPH step
// holding `substeps` contact-bound DEM sub-steps).
#include <benchmark/benchmark.h>

#include <string>

#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"

namespace {

const char* kPaper = MRF_SOURCE_DIR "/experiments/scenes/paper_demsph_stokes.toml";

void BM_PaperStep(benchmark::State& state, const char* model_id, const char* integrator) {
  const auto scene = mrf::load_scene(kPaper, {std::string("scene.model=\"") + model_id + "\"",
                                              std::string("numerics.integrator=\"") + integrator + "\""});
  mrf::BuiltModel b = mrf::build_model(scene);
  mrf::Model& m = *b.model;
  for (int i = 0; i < 20; ++i) m.step();  // leave the random start
  const double t0 = m.time();
  long steps = 0;
  for (auto _ : state) {
    m.step();
    ++steps;
  }
  const double per_step = (m.time() - t0) / static_cast<double>(steps);
  state.counters["mean_dt_s"] = per_step;
  state.counters["s_per_strain"] = benchmark::Counter(
      1.0 / (per_step * scene.config.shear_rate), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["n_fluid"] = static_cast<double>(b.summary.n_fluid);
}
BENCHMARK_CAPTURE(BM_PaperStep, dem_stokes_auto, "dem_stokes", "auto")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperStep, demsph_stokes_auto, "demsph_stokes", "auto")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperStep, demsph_dd_auto, "demsph_dd", "auto")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperStep, demsph_dd_inertial, "demsph_dd", "verlet_exp")
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
