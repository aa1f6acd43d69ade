// kernel_rows (fluid/kernel.hpp) with Google Highway: compiled for every
// instruction set Highway targets here, the best one the machine has chosen
// at the first call, as scene/pair_kernel_simd.cpp. The expressions are
// KernelW's, operation for operation, so the result is the scalar one bit
// for bit; the tail shorter than a vector runs KernelW itself.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fluid/kernel_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <cmath>

#include "mrf/fluid/kernel.hpp"

HWY_BEFORE_NAMESPACE();
namespace mrf {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void KernelRows(const KernelW& k, const double* r2, std::size_t n, double* w, double* f) {
  const double h = k.h, alpha = k.alpha;
  const hn::ScalableTag<double> d;
  const std::size_t lanes = hn::Lanes(d);
  const auto vh = hn::Set(d, h), valpha = hn::Set(d, alpha), vm5alpha = hn::Set(d, -5.0 * alpha),
             vhh = hn::Set(d, h * h), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5), two = hn::Set(d, 2.0),
             support = hn::Set(d, k_kernel_support);
  std::size_t p = 0;
  for (; p + lanes <= n; p += lanes) {
    const auto q = hn::Div(hn::Sqrt(hn::LoadU(d, r2 + p)), vh);
    const auto inside = hn::Lt(q, support);
    const auto t = hn::Sub(one, hn::Mul(half, q));
    const auto t3 = [&](auto c) { return hn::Mul(hn::Mul(hn::Mul(c, t), t), t); };
    // alpha t t t t (2q + 1) and -5 alpha t t t / (h h), left to right as KernelW
    const auto wv = hn::Mul(hn::Mul(t3(valpha), t), hn::Add(hn::Mul(two, q), one));
    const auto fv = hn::Div(t3(vm5alpha), vhh);
    hn::StoreU(hn::IfThenElseZero(inside, wv), d, w + p);
    hn::StoreU(hn::IfThenElseZero(inside, fv), d, f + p);
  }
  for (; p < n; ++p) {
    const double r = std::sqrt(r2[p]);
    w[p] = k(r);
    f[p] = k.dwdr_over_r(r);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace mrf
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mrf {
HWY_EXPORT(KernelRows);

void kernel_rows(const KernelW& k, const double* r2, std::size_t n, double* w, double* dwdr_over_r) {
  HWY_DYNAMIC_DISPATCH(KernelRows)(k, r2, n, w, dwdr_over_r);
}
}  // namespace mrf
#endif
