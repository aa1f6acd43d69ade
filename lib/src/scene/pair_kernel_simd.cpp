// The free-free rows of the pair laws (DipoleX or the quasi-static driver's
// DipoleXShiftedForce, with HertzPair; every pair in range inside the dipole
// cut-off) on the vector units, with Google
// Highway: compiled for every instruction set Highway targets on this
// architecture (AVX-512, AVX2 + FMA, SSE4, ...), the best one the machine
// has chosen at the first call (HWY_DYNAMIC_DISPATCH), so one binary runs at
// full width everywhere.
//
// A row's partners are taken a vector at a time from padded copies of the
// coordinates: loaded and transposed on AVX2 and AVX-512, gathered
// elsewhere; the laws
// of forces/ (dipole_x_law, hertz_law_t) evaluated on whole vectors; and
// the partners' forces decremented in a padded buffer (a row's partners are
// distinct, so lanes never collide). A pair beyond the range gets 1/r = 0,
// so its dipole force is 0; the lanes past a row's end take a far dummy
// partner. The Hertz law runs only on vectors with a contact in them.
//
// The loop is bound by latency, not by arithmetic: each vector's chain runs
// from the index loads through the wrap, r^2, a square root and a division
// to the laws and the stores. So 1/r is sqrt(r^2) * (1 / r^2) (the two
// divider operations in parallel), one mask on 1/r serves every force
// component, the wrap rounds with one instruction, the loop is
// software-pipelined by one vector (the geometry and 1/r of the next vector
// issued before the laws of this one), and a row's last vector is padded
// with the dummy instead of a scalar tail. The gain of each, and what was
// tried and not kept: docs/performance.md, "Pair-kernel floating-point rate"
// (session 17's table).
//
// The pair forces are the scalar loop's expressions except 1/r (a few ulp
// from 1/sqrt), and the row sums run in another order, so forces and sums
// agree with free_rows to round-off (PairLoop.VectorKernelEqualsTheScalarLoop
// in verification/forces/test_pair_loop.cpp).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "scene/pair_kernel_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cmath>

#include "mrf/quasistatic/shifted_dipole.hpp"
#include "mrf/scene/dem_forces.hpp"

HWY_BEFORE_NAMESPACE();
namespace mrf {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
#include "mrf/forces/laws-inl.h"  // the laws, compiled for this target

// 1/sqrt(v). On AVX-512 the 14-bit estimate of rsqrt14 refined by two Newton
// steps, y (3 - v y^2) / 2 (error 2^-56 before rounding, a few ulp after),
// which costs less than a sqrt and a division; elsewhere sqrt(v) * (1/v),
// whose two operations run side by side (1/sqrt(v) chains them).
template <class V>
HWY_INLINE V inverse_sqrt(V v) {
#if HWY_TARGET == HWY_AVX3
  const hn::DFromV<V> d;
  const auto half = hn::Set(d, 0.5), three = hn::Set(d, 3.0);
  auto y = V{_mm512_rsqrt14_pd(v.raw)};
  y = hn::Mul(hn::Mul(half, y), hn::NegMulAdd(hn::Mul(v, y), y, three));
  y = hn::Mul(hn::Mul(half, y), hn::NegMulAdd(hn::Mul(v, y), y, three));
  return y;
#else
  return hn::Mul(hn::Sqrt(v), hn::Div(hn::Set(hn::DFromV<V>(), 1.0), v));
#endif
}

using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;

// The vector form of each dipole evaluator the kernel serves: its
// parameters broadcast once, and the law of laws-inl.h on whole vectors.
template <class Dipole>
struct VectorDipole;
template <>
struct VectorDipole<DipoleX> {
  V pref;
  VectorDipole(D d, const DipoleX& law) : pref(hn::Set(d, law.pref)) {}
  template <class Num>
  V eval(V dx, V dy, V dz, V /*r2*/, V inv_r, V& fx, V& fy, V& fz, Num num) const {
    return dipole_x_law(pref, dx, dy, dz, inv_r, fx, fy, fz, num);
  }
};
template <>
struct VectorDipole<DipoleXShiftedForce> {  // the quasi-static driver's law
  V pref, cutoff, inv_rc;
  VectorDipole(D d, const DipoleXShiftedForce& law)
      : pref(hn::Set(d, law.pref)), cutoff(hn::Set(d, law.cutoff)), inv_rc(hn::Set(d, law.inv_rc)) {}
  template <class Num>
  V eval(V dx, V dy, V dz, V r2, V inv_r, V& fx, V& fy, V& fz, Num num) const {
    return dipole_x_shifted_law(pref, cutoff, inv_rc, dx, dy, dz, inv_r, hn::Mul(r2, inv_r), fx, fy, fz, num);
  }
};

template <class Dipole>
void FreeRowsOf(const DemPairLaws<Dipole, HertzPair>& laws, const Box& box, const std::vector<Vec3>& x,
                const PairRows& rows, std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f,
                PairSums& out) {
  const D d;
  const hn::RebindToSigned<D> di;                 // int64 lanes: the gather indices
  const hn::Rebind<std::uint32_t, D> du;          // the list's uint32 partner indices
  const hn::RebindToUnsigned<D> du64;
  const std::size_t lanes = hn::Lanes(d);
  const Dipole dipole = laws.dipole;
  const VectorDipole<Dipole> vdipole(d, dipole);
  const double k_hertz = laws.contact.k, two_r = laws.contact.sum_radii;
  const double rc2 = laws.dipole_cutoff * laws.dipole_cutoff, contact2 = two_r * two_r;
  const double range2 = std::max(rc2, contact2);
  const MinImageYZ mi(box);
  const auto num = [&d](double v) { return hn::Set(d, v); };
  const auto vsqrt = [](V v) { return hn::Sqrt(v); };
  const auto vk = hn::Set(d, k_hertz), vtwo_r = hn::Set(d, two_r);
  const auto vrange2 = hn::Set(d, range2), vcontact2 = hn::Set(d, contact2), zero = hn::Zero(d);
  const auto ly = hn::Set(d, mi.ly), inv_ly = hn::Set(d, mi.inv_ly), lz = hn::Set(d, mi.lz), inv_lz = hn::Set(d, mi.inv_lz);
  const std::uint32_t* ks = rows.k.data();
  double* fs = f.data()->data();
  // Padded copies, (x, y, z, 0) per sphere. On AVX2, which has no scatter
  // (Highway stores lane by lane) and whose gathers are slow on Zen 2, the
  // partners' coordinates and forces move by aligned 4-wide loads and
  // stores of them and 4 x 4 transposes (a 4-wide access to the packed Vec3
  // array would overlap the next sphere, and such a load cannot take its
  // data from a store to that sphere still in flight). AVX-512 does the
  // same with two partners to a register (its gathers and scatters, 3 + 6
  // per 8-pair vector, held the kernel to half the speed:
  // docs/performance.md, session 43); other targets gather and scatter.
  // The partners' forces collect in fp, added to f at the end. One more
  // sphere, far beyond every range (its r^2 is finite, 1e200 m^2), fills
  // the lanes past the end of a row, where 1/r = 0 gives it no force: a
  // row's last vector needs no scalar tail.
  struct alignas(32) Padded {
    double v[4];
  };
  thread_local std::vector<Padded> xp, fp;
  const std::size_t n_free = x.size();
  const auto dummy = static_cast<std::uint32_t>(n_free);
  xp.resize(n_free + 1);
  fp.assign(n_free + 1, Padded{});
  for (std::size_t k = 0; k < n_free; ++k) xp[k] = Padded{{x[k].x(), x[k].y(), x[k].z(), 0.0}};
  xp[n_free] = Padded{{1e100, 0.0, 0.0, 0.0}};
  const double* xa = xp.data()->v;
  double* fa = fp.data()->v;
  struct Geometry {  // of one vector of pairs
    V dx, dy, dz, r2, inv_r;
    hn::Mask<D> in_range;
  };
  constexpr std::size_t k_max_lanes = 8;  // AVX-512's doubles
  std::uint32_t tail_k[k_max_lanes];      // a row's last vector: its partners, then the dummy
  auto vir_mag = zero, e_dip = zero, vir_con = zero, e_hertz = zero, max_h = zero;
  for (std::size_t i = row_begin; i < row_end; ++i) {
    const auto vxi = hn::Set(d, xa[4 * i]), vyi = hn::Set(d, xa[4 * i + 1]), vzi = hn::Set(d, xa[4 * i + 2]);
    auto fx = zero, fy = zero, fz = zero;
    std::size_t n = rows.start[i];
    const std::size_t end = rows.start[i + 1];
    // the partners of the vector from entry m
    const auto partners = [&](std::size_t m) -> const std::uint32_t* {
      if (m + lanes <= end) return ks + m;
      for (std::size_t l = 0; l < lanes; ++l) tail_k[l] = m + l < end ? ks[m + l] : dummy;
      return tail_k;
    };
    // Software-pipelined by one vector: the geometry and 1/r of the next
    // vector are issued before the laws of this one, so the long latency
    // of the square root and the division overlaps the laws' work instead
    // of filling the scheduler with uops that wait for it.
    const auto geometry = [&](std::size_t m) {
      const std::uint32_t* k = partners(m);
#if HWY_TARGET == HWY_AVX2
      const __m256d q0 = _mm256_load_pd(xa + 4 * std::size_t{k[0]}), q1 = _mm256_load_pd(xa + 4 * std::size_t{k[1]}),
                    q2 = _mm256_load_pd(xa + 4 * std::size_t{k[2]}), q3 = _mm256_load_pd(xa + 4 * std::size_t{k[3]});
      const __m256d t0 = _mm256_unpacklo_pd(q0, q1), t1 = _mm256_unpackhi_pd(q0, q1);  // x0 x1 z0 z1, y0 y1 0 0
      const __m256d t2 = _mm256_unpacklo_pd(q2, q3), t3 = _mm256_unpackhi_pd(q2, q3);
      const V px{_mm256_permute2f128_pd(t0, t2, 0x20)}, py{_mm256_permute2f128_pd(t1, t3, 0x20)},
          pz{_mm256_permute2f128_pd(t0, t2, 0x31)};
#elif HWY_TARGET == HWY_AVX3
      // partners l and l + 4 side by side, then the AVX2 transpose in each
      // half: unpack within 128-bit lanes, then one two-source permute
      const auto pair_of = [&](std::size_t l) {
        return _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_load_pd(xa + 4 * std::size_t{k[l]})),
                                  _mm256_load_pd(xa + 4 * std::size_t{k[l + 4]}), 1);
      };
      const __m512d a0 = pair_of(0), a1 = pair_of(1), a2 = pair_of(2), a3 = pair_of(3);
      const __m512d t0 = _mm512_unpacklo_pd(a0, a1), t1 = _mm512_unpackhi_pd(a0, a1);  // x0 x1 z0 z1 x4 x5 z4 z5, y..
      const __m512d t2 = _mm512_unpacklo_pd(a2, a3), t3 = _mm512_unpackhi_pd(a2, a3);  // x2 x3 z2 z3 x6 x7 z6 z7, y..
      const __m512i even = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
      const __m512i odd = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
      const V px{_mm512_permutex2var_pd(t0, even, t2)}, py{_mm512_permutex2var_pd(t1, even, t3)},
          pz{_mm512_permutex2var_pd(t0, odd, t2)};
#else
      const auto k4 = hn::ShiftLeft<2>(hn::BitCast(di, hn::PromoteTo(du64, hn::LoadU(du, k))));  // x of k in xp
      const auto px = hn::GatherIndex(d, xa, k4), py = hn::GatherIndex(d, xa + 1, k4),
                 pz = hn::GatherIndex(d, xa + 2, k4);
#endif
      Geometry g;
      g.dx = hn::Sub(vxi, px);
      const auto dy = hn::Sub(vyi, py), dz = hn::Sub(vzi, pz);
      // MinImageYZ's wrap; Round is its round_nearest (to even) in one instruction
      g.dy = hn::NegMulAdd(ly, hn::Round(hn::Mul(dy, inv_ly)), dy);
      g.dz = hn::NegMulAdd(lz, hn::Round(hn::Mul(dz, inv_lz)), dz);
      g.r2 = hn::Add(hn::Add(hn::Mul(g.dx, g.dx), hn::Mul(g.dy, g.dy)), hn::Mul(g.dz, g.dz));
      // A pair beyond the range gets 1/r = 0, which makes each dipole law's
      // force 0; its energy and its Hertz overlap are masked.
      g.in_range = hn::Lt(g.r2, vrange2);
      g.inv_r = hn::IfThenElseZero(g.in_range, inverse_sqrt(g.r2));
      return g;
    };
    if (n == end) continue;
    Geometry g = geometry(n);
    for (;;) {
      const std::size_t next = n + lanes;
      const bool more = next < end;
      Geometry gn;
      if (more) gn = geometry(next);
      const V dx = g.dx, dy = g.dy, dz = g.dz, r2 = g.r2, inv_r = g.inv_r;
      V gx, gy, gz;
      const auto ed = vdipole.eval(dx, dy, dz, r2, inv_r, gx, gy, gz, num);
      e_dip = hn::Add(e_dip, hn::IfThenElseZero(g.in_range, ed));
      vir_mag = hn::Add(vir_mag, hn::Mul(dx, gz));
      const auto in_contact = hn::Lt(r2, vcontact2);
      if (!hn::AllFalse(d, in_contact)) {  // contacts are rare: most vectors skip the Hertz law
        const auto h = hn::IfThenElseZero(in_contact, hn::Max(hn::Sub(vtwo_r, hn::Mul(r2, inv_r)), zero));
        V force, energy;
        hertz_law_t(h, vk, force, energy, num, vsqrt);
        const auto f_over_r = hn::Mul(force, inv_r);
        vir_con = hn::Add(vir_con, hn::Mul(dx, hn::Mul(f_over_r, dz)));
        e_hertz = hn::Add(e_hertz, energy);
        max_h = hn::Max(max_h, h);
        gx = hn::Add(gx, hn::Mul(f_over_r, dx));
        gy = hn::Add(gy, hn::Mul(f_over_r, dy));
        gz = hn::Add(gz, hn::Mul(f_over_r, dz));
      }
      fx = hn::Add(fx, gx), fy = hn::Add(fy, gy), fz = hn::Add(fz, gz);
      const std::uint32_t* k = partners(n);
#if HWY_TARGET == HWY_AVX2
      {  // the transpose back: (gx, gy, gz, 0) per partner, subtracted from its row of fp
        const __m256d zero4 = _mm256_setzero_pd();
        const __m256d u0 = _mm256_unpacklo_pd(gx.raw, gy.raw), u1 = _mm256_unpackhi_pd(gx.raw, gy.raw);
        const __m256d u2 = _mm256_unpacklo_pd(gz.raw, zero4), u3 = _mm256_unpackhi_pd(gz.raw, zero4);
        const __m256d g4[4] = {_mm256_permute2f128_pd(u0, u2, 0x20), _mm256_permute2f128_pd(u1, u3, 0x20),
                               _mm256_permute2f128_pd(u0, u2, 0x31), _mm256_permute2f128_pd(u1, u3, 0x31)};
        for (std::size_t l = 0; l < 4; ++l) {
          double* fk = fa + 4 * std::size_t{k[l]};
          _mm256_store_pd(fk, _mm256_sub_pd(_mm256_load_pd(fk), g4[l]));
        }
      }
#elif HWY_TARGET == HWY_AVX3
      {  // the transpose back: (gx, gy, gz, 0) of partners l and l + 2 in one
         // register, each half subtracted from its partner's row of fp
        const __m512d u0 = _mm512_unpacklo_pd(gx.raw, gy.raw), u1 = _mm512_unpackhi_pd(gx.raw, gy.raw);
        const __m512d u2 = _mm512_unpacklo_pd(gz.raw, _mm512_setzero_pd()),
                      u3 = _mm512_unpackhi_pd(gz.raw, _mm512_setzero_pd());
        const __m512i first = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
        const __m512i second = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
        const __m512d g02 = _mm512_permutex2var_pd(u0, first, u2), g46 = _mm512_permutex2var_pd(u0, second, u2);
        const __m512d g13 = _mm512_permutex2var_pd(u1, first, u3), g57 = _mm512_permutex2var_pd(u1, second, u3);
        const __m256d g8[8] = {_mm512_castpd512_pd256(g02), _mm512_castpd512_pd256(g13),
                               _mm512_extractf64x4_pd(g02, 1), _mm512_extractf64x4_pd(g13, 1),
                               _mm512_castpd512_pd256(g46), _mm512_castpd512_pd256(g57),
                               _mm512_extractf64x4_pd(g46, 1), _mm512_extractf64x4_pd(g57, 1)};
        for (std::size_t l = 0; l < 8; ++l) {  // lanes of the dummy write the same 0 - 0 to the same place
          double* fk = fa + 4 * std::size_t{k[l]};
          _mm256_store_pd(fk, _mm256_sub_pd(_mm256_load_pd(fk), g8[l]));
        }
      }
#else
      {  // lanes of the dummy write the same 0 - 0 to the same place
        const auto k4 = hn::ShiftLeft<2>(hn::BitCast(di, hn::PromoteTo(du64, hn::LoadU(du, k))));
        hn::ScatterIndex(hn::Sub(hn::GatherIndex(d, fa, k4), gx), d, fa, k4);
        hn::ScatterIndex(hn::Sub(hn::GatherIndex(d, fa + 1, k4), gy), d, fa + 1, k4);
        hn::ScatterIndex(hn::Sub(hn::GatherIndex(d, fa + 2, k4), gz), d, fa + 2, k4);
      }
#endif
      if (!more) break;
      n = next;
      g = gn;
    }
    fs[3 * i] += hn::GetLane(hn::SumOfLanes(d, fx));
    fs[3 * i + 1] += hn::GetLane(hn::SumOfLanes(d, fy));
    fs[3 * i + 2] += hn::GetLane(hn::SumOfLanes(d, fz));
  }
  for (std::size_t k = 0; k < n_free; ++k) fs[3 * k] += fa[4 * k], fs[3 * k + 1] += fa[4 * k + 1], fs[3 * k + 2] += fa[4 * k + 2];
  out.virial_mag_xz += hn::GetLane(hn::SumOfLanes(d, vir_mag));
  out.energy_dipole += laws.dipole.energy_scale() * hn::GetLane(hn::SumOfLanes(d, e_dip));
  out.virial_con_xz += hn::GetLane(hn::SumOfLanes(d, vir_con));
  out.energy_hertz += hn::GetLane(hn::SumOfLanes(d, e_hertz));
  out.max_overlap = std::max(out.max_overlap, hn::GetLane(hn::MaxOfLanes(d, max_h)));
}

void FreeRows(const DemPairLaws<>& laws, const Box& box, const std::vector<Vec3>& x, const PairRows& rows,
              std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f, PairSums& out) {
  FreeRowsOf(laws, box, x, rows, row_begin, row_end, f, out);
}
void FreeRowsShifted(const DemPairLaws<DipoleXShiftedForce, HertzPair>& laws, const Box& box,
                     const std::vector<Vec3>& x, const PairRows& rows, std::size_t row_begin, std::size_t row_end,
                     std::vector<Vec3>& f, PairSums& out) {
  FreeRowsOf(laws, box, x, rows, row_begin, row_end, f, out);
}

const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace mrf
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mrf {
HWY_EXPORT(FreeRows);
HWY_EXPORT(FreeRowsShifted);
HWY_EXPORT(TargetName);

namespace detail {
void free_rows_simd(const DemPairLaws<>& laws, const Box& box, const std::vector<Vec3>& x, const PairRows& rows,
                    std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f, PairSums& s) {
  HWY_DYNAMIC_DISPATCH(FreeRows)(laws, box, x, rows, row_begin, row_end, f, s);
}
void free_rows_simd_shifted(const DemPairLaws<DipoleXShiftedForce, HertzPair>& laws, const Box& box,
                            const std::vector<Vec3>& x, const PairRows& rows, std::size_t row_begin,
                            std::size_t row_end, std::vector<Vec3>& f, PairSums& s) {
  HWY_DYNAMIC_DISPATCH(FreeRowsShifted)(laws, box, x, rows, row_begin, row_end, f, s);
}
}  // namespace detail

const char* pair_kernel_target() { return HWY_DYNAMIC_DISPATCH(TargetName)(); }
}  // namespace mrf
#endif
