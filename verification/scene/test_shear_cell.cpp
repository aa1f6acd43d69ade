// The placement's numbering: the spheres come in slabs across the gap, so
// consecutive blocks of spheres (the threads' shares of the contact solve
// and the pair lists) are regions of the cell that touch only at their
// faces, and stay so under shear along z.
#include <gtest/gtest.h>

#include <algorithm>

#include "mrf/scene/shear_cell.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6;

SceneConfig paper_like(std::uint64_t seed) {
  SceneConfig c;
  c.radius = R;
  c.gap = 150e-6;
  c.ly = 50e-6;
  c.lz = 120e-6;
  c.volume_fraction = 0.3;
  c.seed = seed;
  return c;
}

// Pairs closer than 2.2 R (touching or about to) whose two spheres fall in
// different halves of the numbering, as a share of all such pairs.
double share_across_halves(const std::vector<Vec3>& x, const Box& box) {
  const std::size_t half = x.size() / 2;
  long near = 0, across = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j)
      if (box.min_image(x[i] - x[j]).norm() < 2.2 * R) {
        ++near;
        across += (i < half) != (j < half);
      }
  EXPECT_GT(near, 100);
  return static_cast<double>(across) / static_cast<double>(near);
}

TEST(Placement, NumberedInSlabsAcrossTheGap) {
  for (std::uint64_t seed : {1, 2}) {
    const SceneConfig c = paper_like(seed);
    const FreeParticles p = place_particles(c);
    ASSERT_EQ(p.size(), particle_count(c));
    // x never falls back by more than one insertion cell (at most 4R wide)
    double highest = -c.gap;
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_GT(p.x[i].x(), highest - 4 * R) << "sphere " << i << ", seed " << seed;
      highest = std::max(highest, p.x[i].x());
    }
    // two halves of the numbering share one face across the gap (about 2R of
    // its 150 um): a few per cent of the near pairs, where a random numbering
    // puts half of them across
    const Box box{c.gap, c.ly, c.lz};
    EXPECT_LT(share_across_halves(p.x, box), 0.08) << "seed " << seed;
    std::vector<Vec3> shuffled = p.x;
    Rng rng(seed);
    for (std::size_t i = shuffled.size(); i > 1; --i)
      std::swap(shuffled[i - 1], shuffled[static_cast<std::size_t>(rng.uniform() * static_cast<double>(i))]);
    EXPECT_GT(share_across_halves(shuffled, box), 0.4) << "the test's contrast, seed " << seed;
  }
}

TEST(Placement, ReproducibleAndWithoutOverlap) {
  const SceneConfig c = paper_like(3);
  const FreeParticles a = place_particles(c), b = place_particles(c);
  ASSERT_EQ(a.x, b.x);  // reproducible
  const Box box{c.gap, c.ly, c.lz};
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LE(std::abs(a.x[i].x()), 0.5 * c.gap - 2 * R);
    for (std::size_t j = i + 1; j < a.size(); ++j)
      ASSERT_GE(box.min_image(a.x[i] - a.x[j]).norm(), 2 * R) << i << " " << j;
  }
}

}  // namespace
}  // namespace mrf
