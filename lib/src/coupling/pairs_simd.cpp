// The coupling pairs' range test over their Verlet candidates (coupling/
// pairs_simd.hpp) with Google Highway, compiled for every instruction set
// Highway targets here and dispatched at the first call, as
// fluid/kernel_simd.cpp. Each vector of candidates gathers both ends'
// coordinates, takes the minimum image along y and z with the operations of
// MinImageYZ (this file is compiled with -ffp-contract=off, lib/CMakeLists.txt,
// so no multiply-add is fused where the scalar code has none) and keeps those
// closer than the support by a compressing store, without a branch per
// candidate. A vector in which some candidate has a second periodic image in
// range (boxes narrower than twice the support, such as the paper cell's
// 50 um against 4h = 52 um) goes one candidate at a time, so that each
// image's entry follows its candidate's. The entries, their r^2 and
// separations are the same, bit for bit and in the same order, whatever
// the vector length, the blocks or the threads.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "coupling/pairs_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "coupling/pairs_simd.hpp"
#include "mrf/neighbors/cell_list.hpp"

static_assert(sizeof(mrf::IndexPair) == sizeof(std::uint64_t) && offsetof(mrf::IndexPair, first) == 0,
              "a candidate is read as one 64-bit lane, DEM index in the low half (little-endian)");
static_assert(sizeof(mrf::Vec3) == 3 * sizeof(double), "positions are read as packed x, y, z");
static_assert(std::endian::native == std::endian::little, "the DEM index is the low half of a candidate's lane");

HWY_BEFORE_NAMESPACE();
namespace mrf {
namespace detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void InRangeCandidates(const InRangeQuery& q, std::size_t lo, std::size_t hi, InRange& out) {
  const hn::ScalableTag<double> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::RebindToSigned<decltype(d)> di;
  const std::size_t lanes = hn::Lanes(d);
  const auto ly = hn::Set(d, q.ly), lz = hn::Set(d, q.lz), inv_ly = hn::Set(d, q.inv_ly),
             inv_lz = hn::Set(d, q.inv_lz), magic = hn::Set(d, 6755399441055744.0), rc2 = hn::Set(d, q.rc2);
  const auto low32 = hn::Set(du, 0xFFFFFFFFull);
  const auto times3 = [](auto v) { return hn::Add(hn::ShiftLeft<1>(v), v); };  // 3 x index: the packed x, y, z
  const auto* cand = reinterpret_cast<const std::uint64_t*>(q.candidates);
  std::size_t kept = 0;
  const auto room = [&](std::size_t n) {  // at least n more entries after `kept`
    if (out.ends.size() >= kept + n && (!q.with_sep || out.sx.size() >= kept + n)) return;
    const std::size_t size = std::max(2 * out.ends.size(), kept + n);
    out.ends.resize(size);
    out.r2.resize(size);
    if (q.with_sep) out.sx.resize(size), out.sy.resize(size), out.sz.resize(size);
  };
  room(hi - lo + lanes);
  // One candidate as the scalar search always took it: x is not periodic,
  // so a cheap rejection first; along a periodic axis of length l >= rc at
  // most the next image on the other side, d - sign(d) l, is also in range
  // (|d| <= l/2), and only when l < 2 rc.
  const MinImageYZ mi(Box{1.0, q.ly, q.lz});
  const auto scalar = [&](std::size_t c) {
    const auto [i, a] = q.candidates[c];
    const double* xi = q.dem_x + 3 * std::size_t{i};
    const double* xa = q.sph_x + 3 * std::size_t{a};
    const double dx = xi[0] - xa[0], dx2 = dx * dx;
    if (dx2 >= q.rc2) return;
    room(4);
    const auto put = [&](double ey, double ez, double q2) {
      out.ends[kept] = cand[c];
      out.r2[kept] = q2;
      if (q.with_sep) out.sx[kept] = dx, out.sy[kept] = ey, out.sz[kept] = ez;
      ++kept;
    };
    const double dy = mi.wrap_y(xi[1] - xa[1]), dz = mi.wrap_z(xi[2] - xa[2]);
    const double r2 = dx2 + dy * dy + dz * dz;
    if (r2 < q.rc2) put(dy, dz, r2);
    if (!q.ky && !q.kz) return;
    const double oy = q.ky ? dy - std::copysign(q.ly, dy) : 0.0, oz = q.kz ? dz - std::copysign(q.lz, dz) : 0.0;
    const bool y2 = q.ky && oy * oy < q.rc2, z2 = q.kz && oz * oz < q.rc2;
    const auto image = [&](double ey, double ez) {
      const double q2 = dx2 + ey * ey + ez * ez;
      if (q2 < q.rc2) put(ey, ez, q2);
    };
    if (y2) image(oy, dz);
    if (z2) {
      image(dy, oz);
      if (y2) image(oy, oz);
    }
  };
  std::size_t c = lo;
  for (; c + lanes <= hi; c += lanes) {
    const auto ia = hn::LoadU(du, cand + c);  // (i, a) pairs: i in the low half
    const auto i3 = times3(hn::BitCast(di, hn::And(ia, low32)));
    const auto a3 = times3(hn::BitCast(di, hn::ShiftRight<32>(ia)));
    const auto dx = hn::Sub(hn::GatherIndex(d, q.dem_x, i3), hn::GatherIndex(d, q.sph_x, a3));
    auto dy = hn::Sub(hn::GatherIndex(d, q.dem_x + 1, i3), hn::GatherIndex(d, q.sph_x + 1, a3));
    auto dz = hn::Sub(hn::GatherIndex(d, q.dem_x + 2, i3), hn::GatherIndex(d, q.sph_x + 2, a3));
    // MinImageYZ::wrap: d - l round(d / l), the rounding by the 1.5 2^52 trick
    dy = hn::Sub(dy, hn::Mul(ly, hn::Sub(hn::Add(hn::Mul(dy, inv_ly), magic), magic)));
    dz = hn::Sub(dz, hn::Mul(lz, hn::Sub(hn::Add(hn::Mul(dz, inv_lz), magic), magic)));
    if (q.ky || q.kz) {
      // a second image in range anywhere in the vector: these candidates
      // one by one, so that every image follows its own candidate's entry
      auto near = hn::FirstN(d, 0);  // no lane
      if (q.ky) {
        const auto oy = hn::Sub(dy, hn::CopySign(ly, dy));
        near = hn::Or(near, hn::Lt(hn::Mul(oy, oy), rc2));
      }
      if (q.kz) {
        const auto oz = hn::Sub(dz, hn::CopySign(lz, dz));
        near = hn::Or(near, hn::Lt(hn::Mul(oz, oz), rc2));
      }
      if (!hn::AllFalse(d, near)) {
        for (std::size_t k = c; k < c + lanes; ++k) scalar(k);
        continue;
      }
    }
    room(lanes);
    const auto q2 = hn::Add(hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy)), hn::Mul(dz, dz));
    const auto in = hn::Lt(q2, rc2);
    const std::size_t n = hn::CompressStore(ia, hn::RebindMask(du, in), du, out.ends.data() + kept);
    hn::CompressStore(q2, in, d, out.r2.data() + kept);
    if (q.with_sep) {
      hn::CompressStore(dx, in, d, out.sx.data() + kept);
      hn::CompressStore(dy, in, d, out.sy.data() + kept);
      hn::CompressStore(dz, in, d, out.sz.data() + kept);
    }
    kept += n;
  }
  for (; c < hi; ++c) scalar(c);  // the tail
  out.n = kept;
}

}  // namespace HWY_NAMESPACE
}  // namespace detail
}  // namespace mrf
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mrf::detail {
HWY_EXPORT(InRangeCandidates);

void in_range_candidates(const InRangeQuery& q, std::size_t lo, std::size_t hi, InRange& out) {
  HWY_DYNAMIC_DISPATCH(InRangeCandidates)(q, lo, hi, out);
}
}  // namespace mrf::detail
#endif
