// The coupled mobility's product (coupling/fluid_response.hpp), the two
// gathers in every CG iteration of the coupled contact solve: on the paper
// cell's density (gap 150 um, 50 x 120 um, SPH dx = 10 um, h = 13 um, 4125
// particles at random between the walls), one thread. Counter: entries
// (DEM-SPH pairs, images merged) per second, each entry read by both passes.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <random>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/coupling/fluid_response.hpp"

namespace {

void BM_FluidResponseAdd(benchmark::State& state) {
  omp_set_num_threads(1);
  const double gap = 150e-6, ly = 50e-6, lz = 120e-6, dx = 10e-6, h = 1.3 * dx;
  const mrf::Box box{gap, ly, lz};
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<mrf::Vec3> sph, dem;
  for (double x = 0.5 * dx; x < gap; x += dx)
    for (double y = 0; y < ly - 1e-12; y += dx)
      for (double z = 0; z < lz - 1e-12; z += dx) sph.emplace_back(x - 0.5 * gap, y, z);
  for (int i = 0; i < 4125; ++i) dem.emplace_back(gap * (0.48 * (2 * unit(rng) - 1)), ly * unit(rng), lz * unit(rng));
  const auto pairs = mrf::coupling_pairs(dem, sph, box, h);
  const double mass = 1000.0 * dx * dx * dx;
  std::vector<double> rho(sph.size(), 700.0), s(dem.size(), 0.0);
  for (const auto& q : pairs) s[q.i] += mass / rho[q.a] * q.w;
  mrf::FluidResponse response;
  response.set(dem.size(), pairs, s, rho, mass);
  std::vector<mrf::Vec3> f(dem.size()), y(dem.size(), mrf::Vec3::Zero());
  for (auto& v : f) v = mrf::Vec3(unit(rng), unit(rng), unit(rng));
  for (auto _ : state) {
    response.add(f, 1e-12, y);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["entries"] = static_cast<double>(pairs.size());
  state.counters["entries_per_s"] =
      benchmark::Counter(static_cast<double>(pairs.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_FluidResponseAdd)->Unit(benchmark::kMicrosecond);

}  // namespace
