// One step of each model on the paper scene (gap 150 um, 50 x 120 um, phi
// 0.30, dipole cutoff 4 d; SPH dx = 10 um, h = 13 um for the coupled models),
// side by side in one run. A coupled step is one SPH step holding `substeps`
// DEM sub-steps; the counter s_per_dem_step divides by them, so it compares
// directly with one dem_stokes step (same contact-bound DEM step size).
#include <benchmark/benchmark.h>

#include <string>

#include "mrf/forces/drag.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/coupled_model.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/run_coupled.hpp"

namespace {

const char* kPaper = MRF_SOURCE_DIR "/experiments/scenes/paper_demsph_stokes.toml";

void BM_DemStokesStep(benchmark::State& state) {
  const auto scene = mrf::load_scene(kPaper, {"scene.model=\"dem_stokes\"", "numerics.integrator=\"verlet_exp\""});
  const mrf::DemParams p = mrf::dem_params(scene.config);
  const auto ts = mrf::choose_time_step(scene, p);
  mrf::ShearCell cell = mrf::build_shear_cell(scene.config);
  for (std::size_t i = 0; i < cell.free.size(); ++i)
    cell.free.v[i] = mrf::couette_velocity(cell.free.x[i], scene.config.shear_rate);
  mrf::DemModel model(std::move(cell), p, ts.scheme, ts.dt);
  for (int i = 0; i < 200; ++i) model.step();  // leave the random start
  for (auto _ : state) model.step();
  state.counters["s_per_dem_step"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["dt_dem"] = ts.dt;
}
BENCHMARK(BM_DemStokesStep)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_CoupledStep(benchmark::State& state, const char* model_id) {
  const auto scene = mrf::load_scene(kPaper, {std::string("scene.model=\"") + model_id + "\""});
  const mrf::SceneConfig& c = scene.config;
  const mrf::DemParams p = mrf::dem_params(c);
  mrf::ShearCell cell = mrf::build_shear_cell(c);
  for (std::size_t i = 0; i < cell.free.size(); ++i) cell.free.v[i] = mrf::couette_velocity(cell.free.x[i], c.shear_rate);
  mrf::FluidCell fluid = mrf::build_coupled_fluid(c, cell);
  const auto ts = mrf::choose_coupled_time_step(scene, p, fluid, 0.5);
  mrf::CoupledModel model(std::move(cell), p, std::move(fluid), mrf::coupled_drag(c.model), ts.dt_fluid,
                          ts.substeps);
  for (int i = 0; i < 200 / ts.substeps + 1; ++i) model.step();
  for (auto _ : state) model.step();
  state.counters["substeps"] = ts.substeps;
  state.counters["s_per_dem_step"] = benchmark::Counter(
      ts.substeps, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["dt_dem"] = model.dt_dem();
  state.counters["n_fluid"] = static_cast<double>(model.fluid().fluid.size());
}
BENCHMARK_CAPTURE(BM_CoupledStep, demsph_stokes, "demsph_stokes")->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_CoupledStep, demsph_dd, "demsph_dd")->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
