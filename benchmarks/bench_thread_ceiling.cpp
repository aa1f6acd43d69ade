// What two threads can give on this machine, whatever the code: the same
// total work per parallel region split over 1 or 2 OpenMP threads, for
// regions of about 10 us to 3 ms of one thread's work (the implicit
// solver's CG iterations are regions of 15-400 us, docs/performance.md), in
// a compute-bound form (independent multiply-add chains, no memory traffic)
// and a memory-bound one (a triad over arrays of 32 KiB to 32 MiB a vector).
// The ratio t(1 thread) / t(2 threads) of a row is the ceiling of a code
// whose regions look like it (issue 16 asks 1.8x per strain unit), and the
// handoff case what a pass pays when the data it reads was last written by
// the other thread (docs/performance.md, session 41).
//
//   build/benchmarks/bench_thread_ceiling --benchmark_filter=Ceiling
//
// Arguments: threads, then the work per region (compute: multiply-add
// rounds of 8 chains per item, 1024 items; memory: doubles per vector).
// The time of an iteration is the wall time of one region.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdint>
#include <vector>

namespace {

// Each of `items` items runs `rounds` rounds of 8 independent multiply-add
// chains on its own registers: no memory traffic, no sharing.
double chains(std::int64_t rounds, std::int64_t item) {
  double c[8];
  for (int j = 0; j < 8; ++j) c[j] = 1.0 + 1e-3 * static_cast<double>(j + item);
  for (std::int64_t r = 0; r < rounds; ++r)
    for (double& x : c) x = x * 0.999999 + 1e-7;
  return c[0] + c[1] + c[2] + c[3] + c[4] + c[5] + c[6] + c[7];
}

void BM_CeilingCompute(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const std::int64_t rounds = state.range(1), items = 1024;
  std::vector<double> out(static_cast<std::size_t>(items));
  for (auto _ : state) {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::int64_t i = 0; i < items; ++i) out[static_cast<std::size_t>(i)] = chains(rounds, i);
    benchmark::DoNotOptimize(out.data());
  }
}

void BM_CeilingTriad(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const std::size_t n = static_cast<std::size_t>(state.range(1));
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 0.0);
  const auto nn = static_cast<std::int64_t>(n);
  for (auto _ : state) {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::int64_t i = 0; i < nn; ++i) {
      const auto k = static_cast<std::size_t>(i);
      c[k] = a[k] + 0.5 * b[k];
    }
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * nn * 24);
}

// Data that changes threads between regions: two threads, region 1 each
// writes its own half of a vector, region 2 each reads back a half (its own
// when the second argument is 0, the other thread's when 1). Two threads
// on cores that do not share a cache pay for the second form in transfers.
void BM_CeilingHandoff(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const bool swap = state.range(1) != 0;
  std::vector<double> v(n, 1.0);
  double sums[2] = {0, 0};
  const std::size_t half = n / 2;
  for (auto _ : state) {
#pragma omp parallel num_threads(2)
    {
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      for (std::size_t i = t * half; i < (t + 1) * half; ++i) v[i] += 1e-9;
#pragma omp barrier
      const std::size_t h = swap ? 1 - t : t;
      double acc = 0;
      for (std::size_t i = h * half; i < (h + 1) * half; ++i) acc += v[i];
      sums[t] = acc;
    }
    benchmark::DoNotOptimize(sums);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n) * 24);
}

// rounds 1, 10, 100, 1000: about 11 us, 45 us, 0.26 ms and 2.8 ms of one thread here
BENCHMARK(BM_CeilingCompute)
    ->ArgsProduct({{1, 2}, {1, 10, 100, 1000}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
// 4 Ki, 64 Ki, 1 Mi, 4 Mi doubles a vector: 32 KiB (L1) to 32 MiB (memory)
BENCHMARK(BM_CeilingTriad)
    ->ArgsProduct({{1, 2}, {4096, 65536, 1 << 20, 1 << 22}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// 64 Ki and 1 Mi doubles (512 KiB, 8 MiB), own half or the other thread's
BENCHMARK(BM_CeilingHandoff)
    ->ArgsProduct({{65536, 1 << 20}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
