// Gap-spanning clusters (observe/structure.hpp): chains built by hand whose
// connectivity is known, across the touch allowance and the periodic image.
#include "mrf/observe/structure.hpp"
#include "mrf/scene/run_series.hpp"

#include <gtest/gtest.h>

namespace mrf {
namespace {

constexpr double R = 1.0;

// A gap of 12 R: wall spheres (one per side) at x = -6 and +6, and five free
// spheres of a straight chain between them at x = -4, -2, 0, 2, 4 (all
// touching), plus one free sphere far from everything.
ShearCell chain_cell() {
  ShearCell c;
  c.box = Box{12 * R, 20 * R, 20 * R};
  c.walls.x = {Vec3(-6 * R, 5 * R, 5 * R), Vec3(6 * R, 5 * R, 5 * R)};
  c.walls.side = {-1, 1};
  for (int j = -2; j <= 2; ++j) c.free.x.push_back(Vec3(2 * R * j, 5 * R, 5 * R));
  c.free.x.push_back(Vec3(0, 15 * R, 15 * R));
  c.free.v.assign(c.free.x.size(), Vec3::Zero());
  c.free.f.assign(c.free.x.size(), Vec3::Zero());
  return c;
}

TEST(Structure, StraightChainSpansTheGap) {
  const ClusterStats s = cluster_stats(chain_cell(), R);
  EXPECT_DOUBLE_EQ(s.spanning_fraction, 5.0 / 6.0);
  EXPECT_DOUBLE_EQ(s.wall_fraction, 5.0 / 6.0);
  EXPECT_DOUBLE_EQ(s.largest_fraction, 5.0 / 6.0);
  EXPECT_EQ(s.clusters, 2u);
}

TEST(Structure, ABrokenChainTouchesTheWallsButDoesNotSpan) {
  ShearCell c = chain_cell();
  c.free.x.erase(c.free.x.begin() + 2);  // the middle sphere
  const ClusterStats s = cluster_stats(c, R);
  EXPECT_EQ(s.spanning_fraction, 0.0);
  EXPECT_DOUBLE_EQ(s.wall_fraction, 4.0 / 5.0);
  EXPECT_DOUBLE_EQ(s.largest_fraction, 2.0 / 5.0);
  EXPECT_EQ(s.clusters, 3u);
}

TEST(Structure, TouchAllowanceDecidesAGapBetweenTwoSpheres) {
  for (double gap : {0.015, 0.025}) {  // the allowance is 0.02 R
    ShearCell c = chain_cell();
    for (int j = 3; j <= 4; ++j) c.free.x[j].x() += gap * R;  // open a gap between spheres 2 and 3...
    c.walls.x[1].x() += gap * R;                                // ...keeping the rest of the chain touching
    c.box.gap += gap * R;
    const ClusterStats s = cluster_stats(c, R);
    EXPECT_DOUBLE_EQ(s.spanning_fraction, gap < k_cluster_touch ? 5.0 / 6.0 : 0.0) << gap;
  }
}

TEST(Structure, SpheresJoinAcrossThePeriodicBoundaries) {
  for (int axis : {1, 2}) {
    ShearCell c = chain_cell();
    // two more spheres touching through y = 0 (or z = 0): 0.5 R and 1.5 R from the boundary
    Vec3 a(0, 10 * R, 10 * R), b = a;
    a[axis] = 0.5 * R;
    b[axis] = 20 * R - 1.5 * R;
    c.free.x.push_back(a);
    c.free.x.push_back(b);
    const ClusterStats s = cluster_stats(c, R);
    EXPECT_EQ(s.clusters, 3u) << axis;  // the chain, the lone sphere, the pair
    b[axis] -= 0.05 * R;                // 2.05 R apart: beyond the allowance
    c.free.x.back() = b;
    EXPECT_EQ(cluster_stats(c, R).clusters, 4u) << axis;
  }
}

// The structure is sampled at most once per k_structure_sample_strain of
// rows, and the rows that do not sample it leave its mean alone.
TEST(Structure, SampledAtMostOncePerStructureStrain) {
  EXPECT_EQ(structure_stride(0.015), 1);    // a sweep's rows: every one
  EXPECT_EQ(structure_stride(1e-3), 1);
  EXPECT_EQ(structure_stride(2.5e-5), 40);  // one row per step of a short benchmark run
  EXPECT_EQ(structure_stride(3e-4), 4);
  EXPECT_EQ(structure_stride(0.0), 1);      // no shear: every row
  StressSeries series;
  SeriesRow row;
  row.n = 1;
  for (int r = 0; r < 40; ++r) {
    row.clusters.spanning_fraction = r % 4 == 0 ? 0.5 : 0.9;  // 0.9 only on the rows that skip it
    series.push(row, r % 4 == 0);
  }
  RunSummary s;
  series.finish(s);
  EXPECT_EQ(series.rows(), 40u);
  EXPECT_DOUBLE_EQ(s.extra.at("spanning_fraction"), 0.5);
}

}  // namespace
}  // namespace mrf
