// One DEM-Stokes step of the paper scene (gap 150 um, 50 x 120 um, phi 0.30,
// dipole cutoff 4 d), for each integrator, and the pair-force kernel alone.
// An implicit step is one accepted, error-controlled step (rejected attempts
// included); its counters give the Newton and CG iterations per step and the
// mean step length, so time per strain unit = time per step / (dt gdot).
// Counters: particle-steps/s and pair evaluations/s (pairs in the Verlet list).
#include <benchmark/benchmark.h>

#include <memory>

#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/dem_model.hpp"

namespace {

// The model `mrf run` builds for the paper scene with this integrator (Couette
// start, the scene's implicit options), past its random start.
mrf::DemModel paper_model(mrf::IntegratorId scheme) {
  const auto scene = mrf::load_scene(MRF_SOURCE_DIR "/experiments/scenes/paper_dem_stokes.toml",
                                     {std::string("numerics.integrator=") + mrf::to_string(scheme)});
  mrf::BuiltModel b = mrf::build_model(scene);
  mrf::DemModel model = std::move(dynamic_cast<mrf::DemModel&>(*b.model));
  for (int i = 0; i < 200; ++i) model.step();
  return model;
}

void step_counters(benchmark::State& state, const mrf::DemModel& m) {
  const double n = static_cast<double>(m.cell().free.size());
  const double pairs = static_cast<double>(m.lists().ff.size() + m.lists().fw.size());
  state.counters["particle_steps/s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["pairs/s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["particles"] = n;
  state.counters["pairs"] = pairs;
}

void BM_PaperStep(benchmark::State& state, mrf::IntegratorId scheme) {
  mrf::DemModel model = paper_model(scheme);
  for (auto _ : state) model.step();
  step_counters(state, model);
}
BENCHMARK_CAPTURE(BM_PaperStep, verlet_exp, mrf::IntegratorId::verlet_exp)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperStep, overdamped, mrf::IntegratorId::overdamped)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_PaperImplicitStep(benchmark::State& state, mrf::ContactFormulation formulation,
                          mrf::ContactLinearSolver solver) {
  mrf::DemModel model = paper_model(mrf::IntegratorId::implicit);
  mrf::ImplicitOptions o;
  o.formulation = formulation;
  o.solver = solver;
  model.set_implicit_options(o);
  const mrf::ImplicitCounters c0 = model.implicit_counters();
  const long s0 = model.steps();
  const double t0 = model.time();
  for (auto _ : state) model.step();
  step_counters(state, model);
  const mrf::ImplicitCounters& c = model.implicit_counters();
  const double steps = static_cast<double>(model.steps() - s0);
  state.counters["newton/step"] = static_cast<double>(c.newton_iterations - c0.newton_iterations) / steps;
  state.counters["cg/step"] = static_cast<double>(c.linear_iterations - c0.linear_iterations) / steps;
  state.counters["rejected/step"] = static_cast<double>(c.rejected + c.newton_failures - c0.rejected - c0.newton_failures) / steps;
  state.counters["mean_dt_s"] = (model.time() - t0) / steps;
}
BENCHMARK_CAPTURE(BM_PaperImplicitStep, dual, mrf::ContactFormulation::dual, mrf::ContactLinearSolver::pcg)
    ->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperImplicitStep, primal_pcg, mrf::ContactFormulation::primal, mrf::ContactLinearSolver::pcg)
    ->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PaperImplicitStep, primal_eigen_ldlt, mrf::ContactFormulation::primal,
                  mrf::ContactLinearSolver::eigen_ldlt)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_PaperPairForces(benchmark::State& state) {
  mrf::DemModel model = paper_model(mrf::IntegratorId::verlet_exp);
  mrf::ShearCell cell = model.cell();
  for (auto _ : state) {
    auto s = mrf::compute_dem_forces(model.params(), cell.box, cell.free, cell.walls, model.lists());
    benchmark::DoNotOptimize(s);
  }
  step_counters(state, model);
}
BENCHMARK(BM_PaperPairForces)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_PaperNeighbourBuild(benchmark::State& state) {
  mrf::DemModel model = paper_model(mrf::IntegratorId::verlet_exp);
  mrf::DemPairLists lists = model.lists();
  for (auto _ : state) mrf::rebuild_all_pair_lists(lists, model.cell().free, model.cell().walls, model.cell().box);
  state.counters["particles"] = static_cast<double>(model.cell().free.size());
}
BENCHMARK(BM_PaperNeighbourBuild)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
