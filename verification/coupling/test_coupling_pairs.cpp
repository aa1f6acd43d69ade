// The DEM-SPH coupling pairs (coupling/exchange.hpp): the search against a
// brute force and an entry-by-entry enumeration with every periodic image,
// the same list on any number of threads, and the Verlet cache of the pairs
// (the same pairs as a fresh search at every step; rebuilt exactly when its
// skin is spent). Fluid from build_fluid_cell (support/coupling_cell.hpp).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "support/coupling_cell.hpp"

namespace mrf {
namespace {

using namespace mrf::test;  // the fluid cell and particles of support/coupling_cell.hpp

// Two pair lists and their kernel gradients equal entry for entry, bit for bit.
void same_pairs_bit_for_bit(const std::vector<CouplingPair>& a, const std::vector<Vec3>& a_dw,
                            const std::vector<CouplingPair>& b, const std::vector<Vec3>& b_dw) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a_dw.size(), a.size());
  ASSERT_EQ(b_dw.size(), b.size());
  for (std::size_t k = 0; k < b.size(); ++k) {
    ASSERT_EQ(a[k].i, b[k].i) << "entry " << k;
    ASSERT_EQ(a[k].a, b[k].a) << "entry " << k;
    ASSERT_EQ(a[k].w, b[k].w) << "entry " << k;
    ASSERT_EQ(a_dw[k], b_dw[k]) << "entry " << k;
  }
}

TEST(CouplingExchange, PairsMatchBruteForce) {
  const FluidCell c = make_cell();
  const auto dem = random_points(50, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 1);
  const auto pairs = coupling_pairs(dem, c.fluid.x, c.box, c.h);
  EXPECT_EQ(pairs.size(), brute_force_cross_pairs(dem, c.fluid.x, c.box, 2.0 * c.h).size());
}

// Every pair and periodic image against an enumeration written out here,
// entry for entry and bit for bit: (i, a) in order, each image after the
// minimum one (y, z, both), W and its gradient from KernelW. In the default
// box (one image per pair) and in boxes narrower than 4h along y, z and
// both, as the paper cell is along y, with enough points that the vector
// path, its one-at-a-time fallback and the tail all run. A wrong image
// order, a lost image or another rounding of the minimum image fails.
TEST(CouplingExchange, PairsAndImagesMatchAnEnumerationBitForBit) {
  for (const Box& box : {Box{24 * kDx, 12 * kDx, 12 * kDx}, Box{24 * kDx, 5 * kDx, 12 * kDx},
                         Box{24 * kDx, 12 * kDx, 5 * kDx}, Box{24 * kDx, 3 * kDx, 4 * kDx}}) {
    const FluidCell c = make_cell(box);
    const auto dem = random_points(301, -0.5 * box.gap, 0.5 * box.gap, box, 13);
    std::vector<CouplingPair> pairs;
    std::vector<Vec3> dw;
    coupling_pairs(dem, c.fluid.x, box, c.h, pairs, &dw);
    const KernelW k(c.h);
    const double rc = k_kernel_support * c.h, rc2 = rc * rc;
    const MinImageYZ mi(box);
    std::size_t e = 0, images = 0;
    for (std::uint32_t i = 0; i < dem.size(); ++i)
      for (std::uint32_t a = 0; a < c.fluid.size(); ++a) {
        const Vec3 d = mi.delta(dem[i], c.fluid.x[a]);
        std::vector<Vec3> seps{d};  // the minimum image, then the next ones across y, z, both
        const double oy = d.y() - std::copysign(box.ly, d.y()), oz = d.z() - std::copysign(box.lz, d.z());
        const bool ky = box.ly < 2 * rc, kz = box.lz < 2 * rc;
        if (ky) seps.emplace_back(d.x(), oy, d.z());
        if (kz) seps.emplace_back(d.x(), d.y(), oz);
        if (ky && kz) seps.emplace_back(d.x(), oy, oz);
        for (std::size_t m = 0; m < seps.size(); ++m) {
          const Vec3& s = seps[m];
          const double r2 = s.x() * s.x() + s.y() * s.y() + s.z() * s.z();
          if (!(r2 < rc2)) continue;
          ASSERT_LT(e, pairs.size());
          ASSERT_EQ(pairs[e].i, i) << "entry " << e;
          ASSERT_EQ(pairs[e].a, a) << "entry " << e;
          const double r = std::sqrt(r2);
          ASSERT_EQ(pairs[e].w, k(r)) << "entry " << e;
          ASSERT_EQ(dw[e], (s * k.dwdr_over_r(r)).eval()) << "entry " << e;
          images += m > 0;
          ++e;
        }
      }
    EXPECT_EQ(e, pairs.size());
    EXPECT_GT(e, 2000u);
    if (box.ly < 4 * c.h || box.lz < 4 * c.h) {
      EXPECT_GT(images, 50u) << "a narrow box has second images";
    }
  }
}

// The search runs in blocks of DEM particles on threads; the list is the
// same, entry for entry and in the same order, on 1, 2 and 3 threads (and
// above the block threshold, 1000 DEM particles).
TEST(CouplingExchange, PairsAreTheSameOnAnyNumberOfThreads) {
  const FluidCell c = make_cell();
  const auto dem = random_points(2500, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 5);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  std::vector<CouplingPair> one, many;
  std::vector<Vec3> one_dw, many_dw;
  coupling_pairs(dem, c.fluid.x, c.box, c.h, one, &one_dw);
  ASSERT_EQ(one_dw.size(), one.size());
  for (int t : {2, 3}) {
    omp_set_num_threads(t);
    coupling_pairs(dem, c.fluid.x, c.box, c.h, many, &many_dw);
    SCOPED_TRACE(std::to_string(t) + " threads");
    ASSERT_NO_FATAL_FAILURE(same_pairs_bit_for_bit(many, many_dw, one, one_dw));
  }
  omp_set_num_threads(saved);
  EXPECT_TRUE(std::is_sorted(one.begin(), one.end(), [](const CouplingPair& x, const CouplingPair& y) {
    return x.i != y.i ? x.i < y.i : x.a < y.a;
  }));
}

// A box narrower than 4h: a pair interacts through two periodic images, and
// the kernel weight each DEM particle sees must equal the brute-force sum
// over all images (|k| <= 2 covers the support). With a single image the
// weight of a particle near y = 0 would miss the far image.
TEST(CouplingExchange, PairsSumEveryPeriodicImageInNarrowBoxes) {
  const FluidCell c = make_cell(Box{24 * kDx, 3 * kDx, 4 * kDx});  // ly, lz < 4h = 5.2 dx
  const auto dem = random_points(40, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 7);
  const auto pairs = coupling_pairs(dem, c.fluid.x, c.box, c.h);
  std::vector<double> sum(dem.size(), 0.0), expect(dem.size(), 0.0);
  for (const CouplingPair& q : pairs) sum[q.i] += q.w;
  for (std::size_t i = 0; i < dem.size(); ++i)
    for (const Vec3& xa : c.fluid.x)
      for (int ky = -2; ky <= 2; ++ky)
        for (int kz = -2; kz <= 2; ++kz)
          expect[i] += kernel_w((dem[i] - xa + Vec3(0.0, ky * c.box.ly, kz * c.box.lz)).norm(), c.h);
  for (std::size_t i = 0; i < dem.size(); ++i) EXPECT_NEAR(sum[i], expect[i], 1e-12 * expect[i]) << i;
}

// The Verlet cache of the coupling pairs (CouplingPairCache): DEM and SPH
// points carried by a shear flow plus a random non-affine jitter, in a
// normal box and in one narrower than 4h (two periodic images per pair).
// At every step the pairs of the cached candidates equal a fresh search,
// entry for entry and weight for weight, while the cache was rebuilt on
// only some of the steps: the rebuild bound holds and the cache is used.
TEST(CouplingExchange, CachedPairsEqualAFreshSearchAtEveryStep) {
  for (const Box& box : {Box{24 * kDx, 12 * kDx, 12 * kDx}, Box{24 * kDx, 3 * kDx, 4 * kDx}}) {
    const FluidCell c = make_cell(box);
    std::vector<Vec3> dem = random_points(300, -0.5 * box.gap, 0.5 * box.gap, box, 11), sph = c.fluid.x;
    CouplingPairCache cache;
    cache.skin = 0.3 * c.h;
    std::mt19937_64 gen(3);
    std::normal_distribution<double> jitter(0.0, 0.01 * c.h);
    const double d_strain = 2e-3;
    auto move = [&](std::vector<Vec3>& x) {
      for (Vec3& q : x) {
        q += Vec3(jitter(gen), jitter(gen), d_strain * q.x() + jitter(gen));
        q.y() -= box.ly * std::floor(q.y() / box.ly);
        q.z() -= box.lz * std::floor(q.z() / box.lz);
      }
    };
    std::vector<CouplingPair> cached, fresh;
    std::vector<Vec3> cached_dw, fresh_dw;
    const int steps = 200;
    for (int step = 0; step < steps; ++step) {
      if (coupling_cache_stale(cache, dem, sph, box, c.h)) rebuild_coupling_cache(cache, dem, sph, box, c.h);
      coupling_pairs_of(cache.candidates, dem, sph, box, c.h, cached, &cached_dw);
      coupling_pairs(dem, sph, box, c.h, fresh, &fresh_dw);
      SCOPED_TRACE("step " + std::to_string(step));
      ASSERT_NO_FATAL_FAILURE(same_pairs_bit_for_bit(cached, cached_dw, fresh, fresh_dw));
      move(dem);
      move(sph);
      cache.strain += d_strain;
    }
    EXPECT_GT(cache.builds, 2) << "the bound never asked for a rebuild: the test does not test it";
    EXPECT_LT(cache.builds, steps / 4) << "the cache is rebuilt too often to be worth it";
  }
}

// The bound itself: one SPH point moved (non-affinely) by more than the
// skin makes the cache stale, by less than half of it not; so does a
// strain whose affine closing over the reach exceeds the skin.
TEST(CouplingExchange, CacheIsStaleExactlyWhenTheSkinIsSpent) {
  const FluidCell c = make_cell();
  const auto dem = random_points(50, -0.5 * c.box.gap, 0.5 * c.box.gap, c.box, 2);
  CouplingPairCache cache;
  cache.skin = 0.3 * c.h;
  EXPECT_TRUE(coupling_cache_stale(cache, dem, c.fluid.x, c.box, c.h)) << "never built";
  rebuild_coupling_cache(cache, dem, c.fluid.x, c.box, c.h);
  EXPECT_FALSE(coupling_cache_stale(cache, dem, c.fluid.x, c.box, c.h));
  auto sph = c.fluid.x;
  sph[7].y() += 0.45 * cache.skin;
  EXPECT_FALSE(coupling_cache_stale(cache, dem, sph, c.box, c.h));
  sph[7].y() += 0.6 * cache.skin;
  EXPECT_TRUE(coupling_cache_stale(cache, dem, sph, c.box, c.h));
  // points carried affinely by the strain (z += strain x): only the
  // closing |strain| reach of the bound counts
  const double reach = k_kernel_support * c.h + cache.skin;
  auto sheared = [&](std::vector<Vec3> x, double strain) {
    for (Vec3& q : x) q.z() += strain * q.x();
    return x;
  };
  for (double f : {0.9, 1.1}) {
    cache.strain = f * cache.skin / reach;
    EXPECT_EQ(coupling_cache_stale(cache, sheared(dem, cache.strain), sheared(c.fluid.x, cache.strain), c.box, c.h),
              f > 1)
        << "strain " << f << " x skin / reach";
  }
}

}  // namespace
}  // namespace mrf
