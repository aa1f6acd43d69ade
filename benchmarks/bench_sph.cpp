// One SPH step of carrier fluid filling the paper shear cell: gap 150 um,
// 50 x 120 um periodic, dx = 10 um (the spacing of the coupled models,
// REFERENCE §6; h = 13 um, 900 fluid + 360 wall particles), real oil
// (eta = 0.1 Pa s, rho = 1000 kg/m^3), gdot = 100/s. Explicit at its
// automatic dt (viscous limit) and implicit viscosity at its automatic dt
// (CFL limit); the reported counter sim_time_per_s is simulated seconds per
// wall second, the cost that matters.
#include <benchmark/benchmark.h>

#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/wcsph.hpp"

namespace {

mrf::FluidCell paper_cell() {
  mrf::FluidParams p;
  p.viscosity = 0.1;
  p.density = 1000;
  p.spacing = 10e-6;
  p.shear_rate = 100;
  return mrf::build_fluid_cell(mrf::Box{150e-6, 50e-6, 120e-6}, p);
}

void run(benchmark::State& state, mrf::SphImplicit implicit) {
  mrf::FluidCell c = paper_cell();
  const double dt = 0.5 * mrf::smallest(mrf::stability_limits(c, implicit));
  for (auto _ : state) {
    if (implicit != mrf::SphImplicit::none)
      benchmark::DoNotOptimize(mrf::step_implicit(c, dt, implicit));
    else
      mrf::step(c, dt);
  }
  state.counters["dt_s"] = dt;
  state.counters["sim_time_per_s"] = benchmark::Counter(dt * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["n_fluid"] = static_cast<double>(c.fluid.size());
}

// per step, each at its own largest stable step (sim_time_per_s compares them)
void BM_SphStepExplicit(benchmark::State& s) { run(s, mrf::SphImplicit::none); }
void BM_SphStepImplicit(benchmark::State& s) { run(s, mrf::SphImplicit::viscosity); }
void BM_SphStepImplicitPressure(benchmark::State& s) { run(s, mrf::SphImplicit::pressure_viscosity); }

}  // namespace

BENCHMARK(BM_SphStepExplicit)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SphStepImplicit)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SphStepImplicitPressure)->Unit(benchmark::kMicrosecond);
