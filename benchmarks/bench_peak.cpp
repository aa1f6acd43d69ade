// The floating-point peak of one core, measured: independent chains of
// vector multiply-adds (12 accumulators, enough to cover the FMA latency on
// two pipes) at the widest instruction set Highway finds on the machine, the
// same dispatch the pair kernel uses. The counter `flops` is double-precision
// flop/s (an FMA counts 2). docs/performance.md sets the pair kernel's rate
// (BM_PaperPairForces in bench_dem_step) against it.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "bench_peak.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <benchmark/benchmark.h>

#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace peak {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// rounds x 12 chains x lanes FMAs; returns a value that depends on all of them.
double FmaChains(std::int64_t rounds) {
  const hn::ScalableTag<double> d;
  const auto a = hn::Set(d, 0.999999), b = hn::Set(d, 1e-7);
  auto c0 = hn::Set(d, 1.0), c1 = hn::Set(d, 1.1), c2 = hn::Set(d, 1.2), c3 = hn::Set(d, 1.3);
  auto c4 = hn::Set(d, 1.4), c5 = hn::Set(d, 1.5), c6 = hn::Set(d, 1.6), c7 = hn::Set(d, 1.7);
  auto c8 = hn::Set(d, 1.8), c9 = hn::Set(d, 1.9), c10 = hn::Set(d, 2.0), c11 = hn::Set(d, 2.1);
  for (std::int64_t r = 0; r < rounds; ++r) {
    c0 = hn::MulAdd(c0, a, b), c1 = hn::MulAdd(c1, a, b), c2 = hn::MulAdd(c2, a, b), c3 = hn::MulAdd(c3, a, b);
    c4 = hn::MulAdd(c4, a, b), c5 = hn::MulAdd(c5, a, b), c6 = hn::MulAdd(c6, a, b), c7 = hn::MulAdd(c7, a, b);
    c8 = hn::MulAdd(c8, a, b), c9 = hn::MulAdd(c9, a, b), c10 = hn::MulAdd(c10, a, b), c11 = hn::MulAdd(c11, a, b);
  }
  const auto s = hn::Add(hn::Add(hn::Add(c0, c1), hn::Add(c2, c3)),
                         hn::Add(hn::Add(hn::Add(c4, c5), hn::Add(c6, c7)), hn::Add(hn::Add(c8, c9), hn::Add(c10, c11))));
  return hn::GetLane(hn::SumOfLanes(d, s));
}
std::size_t Lanes() { return hn::Lanes(hn::ScalableTag<double>()); }
const char* Target() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace peak
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace peak {
HWY_EXPORT(FmaChains);
HWY_EXPORT(Lanes);
HWY_EXPORT(Target);

void BM_FmaPeak(benchmark::State& state) {
  constexpr std::int64_t k_rounds = 1 << 16;
  const double lanes = static_cast<double>(HWY_DYNAMIC_DISPATCH(Lanes)());
  for (auto _ : state) benchmark::DoNotOptimize(HWY_DYNAMIC_DISPATCH(FmaChains)(k_rounds));
  state.counters["flops"] = benchmark::Counter(2.0 * 12.0 * lanes * k_rounds * static_cast<double>(state.iterations()),
                                               benchmark::Counter::kIsRate);
  state.SetLabel(HWY_DYNAMIC_DISPATCH(Target)());
}
BENCHMARK(BM_FmaPeak)->Unit(benchmark::kMicrosecond)->UseRealTime();
}  // namespace peak
#endif
