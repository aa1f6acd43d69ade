// Cell list against the brute-force oracle: identical pair sets on random
// periodic configurations, including boxes too small for 3 cells per axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <omp.h>

#include "mrf/neighbors/cell_list.hpp"

namespace mrf {
namespace {

std::vector<Vec3> random_points(std::size_t n, const Box& box, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(-box.gap / 2, box.gap / 2), uy(0, box.ly),
      uz(0, box.lz);
  std::vector<Vec3> p(n);
  for (auto& q : p) q = Vec3(ux(rng), uy(rng), uz(rng));
  return p;
}

std::vector<IndexPair> sorted(std::vector<IndexPair> v) {
  std::sort(v.begin(), v.end());
  return v;
}

struct Case {
  Box box;
  double cutoff;
};

class CellListVsBruteForce : public ::testing::TestWithParam<Case> {};

TEST_P(CellListVsBruteForce, SelfPairsIdentical) {
  const auto [box, rc] = GetParam();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto pts = random_points(400, box, seed);
    const auto ref = sorted(brute_force_self_pairs(pts, box, rc));
    ASSERT_FALSE(ref.empty());
    EXPECT_EQ(sorted(self_pairs(pts, box, rc)), ref) << "seed " << seed;
  }
}

TEST_P(CellListVsBruteForce, PairRowsHoldTheSamePairs) {
  const auto [box, rc] = GetParam();
  const auto pts = random_points(400, box, 21);
  PairRows rows;
  self_pair_rows(pts, box, rc, rows);
  ASSERT_EQ(rows.start.size(), pts.size() + 1);
  std::vector<IndexPair> flat;
  for (std::uint32_t i = 0; i < pts.size(); ++i)
    for (std::uint32_t n = rows.start[i]; n < rows.start[i + 1]; ++n) {
      EXPECT_GT(rows.k[n], i);  // each pair once, in the row of its smaller index
      flat.emplace_back(i, rows.k[n]);
    }
  EXPECT_EQ(rows.size(), flat.size());
  EXPECT_EQ(sorted(flat), sorted(brute_force_self_pairs(pts, box, rc)));
}

// The rows that build(rows) leaves, built on 1, 2 and 3 threads: the same
// entry for entry, and the brute-force pairs of pts.
template <class Build>
void expect_serial_rows_on_threads(const std::vector<Vec3>& pts, const Box& box, double rc, Build build) {
  const int saved = omp_get_max_threads();
  std::vector<PairRows> by_threads;
  for (int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    PairRows rows;
    build(rows);
    by_threads.push_back(rows);
  }
  omp_set_num_threads(saved);
  for (std::size_t t = 1; t < by_threads.size(); ++t) {
    EXPECT_EQ(by_threads[t].start, by_threads[0].start) << t + 1 << " threads";
    EXPECT_EQ(by_threads[t].k, by_threads[0].k) << t + 1 << " threads";
  }
  std::vector<IndexPair> flat;
  const PairRows& rows = by_threads[2];
  for (std::uint32_t i = 0; i < pts.size(); ++i)
    for (std::uint32_t n = rows.start[i]; n < rows.start[i + 1]; ++n) flat.emplace_back(i, rows.k[n]);
  EXPECT_EQ(sorted(flat), sorted(brute_force_self_pairs(pts, box, rc)));
}

// Above the size where the build runs its rows on threads: the rows are
// the serial build's, entry for entry, for 1, 2 and 3 threads, and hold the
// brute-force pairs (blocks of uneven length and empty rows included).
TEST_P(CellListVsBruteForce, PairRowsOnThreadsEqualTheSerialBuild) {
  const auto [box, rc] = GetParam();
  const auto pts = random_points(3001, box, 31);
  expect_serial_rows_on_threads(pts, box, rc, [&](PairRows& rows) { self_pair_rows(pts, box, rc, rows); });
}

// A rebuild cuts its row blocks by the last list's shares (any numbering):
// still the serial rows, for 1, 2 and 3 threads, after the points moved.
TEST_P(CellListVsBruteForce, RebuiltPairRowsOnThreadsEqualTheSerialBuild) {
  const auto [box, rc] = GetParam();
  auto pts = random_points(3001, box, 41);
  std::sort(pts.begin(), pts.end(), [](const Vec3& a, const Vec3& b) { return a.x() < b.x(); });  // slabs
  auto moved = pts;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-0.3 * rc, 0.3 * rc);
  for (auto& q : moved) {
    q += Vec3(u(rng), u(rng), u(rng));
    q.x() = std::clamp(q.x(), -box.gap / 2, box.gap / 2);
  }
  expect_serial_rows_on_threads(moved, box, rc, [&](PairRows& rows) {
    self_pair_rows(pts, box, rc, rows);
    self_pair_rows(moved, box, rc, rows);
  });
}

TEST_P(CellListVsBruteForce, CrossPairsIdentical) {
  const auto [box, rc] = GetParam();
  const auto a = random_points(300, box, 11);
  const auto b = random_points(200, box, 12);
  const auto ref = sorted(brute_force_cross_pairs(a, b, box, rc));
  ASSERT_FALSE(ref.empty());
  EXPECT_EQ(sorted(cross_pairs(a, b, box, rc)), ref);
}

INSTANTIATE_TEST_SUITE_P(Boxes, CellListVsBruteForce,
                         ::testing::Values(Case{{10.0, 10.0, 10.0}, 1.5},   // many cells
                                           Case{{10.0, 4.0, 10.0}, 1.5},    // 2 cells in y
                                           Case{{3.0, 10.0, 2.5}, 1.1},     // 2 cells in z
                                           Case{{10.0, 7.0, 9.0}, 2.9}));   // uneven widths

TEST(CellList, PeriodicImageIsFound) {
  const Box box{10.0, 10.0, 10.0};
  const std::vector<Vec3> pts{Vec3(0, 0.1, 5), Vec3(0, 9.9, 5)};
  const auto pairs = self_pairs(pts, box, 0.5);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], IndexPair(0, 1));
}

TEST(CellList, XIsNotPeriodic) {
  const Box box{10.0, 10.0, 10.0};
  const std::vector<Vec3> pts{Vec3(-4.9, 5, 5), Vec3(4.9, 5, 5)};
  EXPECT_TRUE(self_pairs(pts, box, 0.5).empty());
}

}  // namespace
}  // namespace mrf

namespace mrf {
namespace {

// The lists store 32-bit offsets: a count past 2^32 - 1 is an error that
// names the list, never a wrapped offset.
TEST(CellList, ListOffsetsPast32BitsAreAnErrorNotAWrap) {
  EXPECT_EQ(checked_index(0, "pair list"), 0u);
  EXPECT_EQ(checked_index(4294967295ull, "pair list"), 4294967295u);
  try {
    checked_index(4294967296ull, "pair list");
    FAIL() << "expected std::length_error";
  } catch (const std::length_error& e) {
    EXPECT_NE(std::string(e.what()).find("pair list: 4294967296 entries"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mrf
