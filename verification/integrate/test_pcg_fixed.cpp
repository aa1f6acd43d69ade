// pcg_fixed (integrate/pcg.hpp): CG on the free block of a symmetric
// positive definite system with some unknowns held at given values, the
// linear algebra of the contact solve's re-solve with clipped contacts at
// zero force. Against the dense solution of the reduced system.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "mrf/integrate/pcg.hpp"

namespace mrf {
namespace {

struct System {
  Eigen::MatrixXd a;
  std::vector<double> b, x0;
  std::vector<char> fixed;
};

System make_system(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m(i, j) = g(rng);
  System s;
  s.a = m.transpose() * m + 0.5 * Eigen::MatrixXd::Identity(n, n);
  s.b.resize(n);
  s.x0.resize(n);
  s.fixed.assign(n, 0);
  for (int i = 0; i < n; ++i) s.b[i] = g(rng), s.x0[i] = g(rng);
  for (int i : {2, 5, 7, 11}) s.fixed[i] = 1;
  return s;
}

// x_F of A_FF x_F = b_F - A_FC x0_C, dense
Eigen::VectorXd reduced_solution(const System& s) {
  std::vector<int> f;
  for (int i = 0; i < static_cast<int>(s.b.size()); ++i)
    if (!s.fixed[i]) f.push_back(i);
  const int nf = static_cast<int>(f.size());
  Eigen::MatrixXd aff(nf, nf);
  Eigen::VectorXd rhs(nf);
  for (int p = 0; p < nf; ++p) {
    rhs(p) = s.b[f[p]];
    for (int j = 0; j < static_cast<int>(s.b.size()); ++j)
      if (s.fixed[j]) rhs(p) -= s.a(f[p], j) * s.x0[j];
    for (int q = 0; q < nf; ++q) aff(p, q) = s.a(f[p], f[q]);
  }
  return aff.llt().solve(rhs);
}

long solve(const System& s, const std::vector<double>& guess, double rtol, std::vector<double>& x) {
  PcgScratch<double> scratch;
  const auto apply = [&](const std::vector<double>& p, std::vector<double>& out) {
    const Eigen::VectorXd y = s.a * Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<long>(p.size()));
    out.assign(y.data(), y.data() + y.size());
  };
  const auto jacobi = [&](const std::vector<double>& r, std::vector<double>& z) {
    z.resize(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) z[i] = r[i] / s.a(static_cast<long>(i), static_cast<long>(i));
  };
  return pcg_fixed(s.b, s.fixed, s.x0, guess, rtol, 1000, apply, jacobi, x, scratch);
}

TEST(PcgFixed, SolvesTheFreeBlockWithTheFixedEntriesHeld) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const System s = make_system(16, seed);
    const Eigen::VectorXd want = reduced_solution(s);
    for (const bool warm : {false, true}) {
      // a guess off the solution (warm) or none (zeros)
      std::vector<double> guess(s.b.size(), 0.0);
      if (warm)
        for (std::size_t i = 0; i < guess.size(); ++i) guess[i] = 0.3 * s.b[i] - 1.0;
      std::vector<double> x;
      const long it = solve(s, guess, 1e-12, x);
      EXPECT_GT(it, 0);
      int p = 0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        if (s.fixed[i]) {
          EXPECT_EQ(x[i], s.x0[i]) << "fixed entry " << i << " moved";
        } else {
          EXPECT_NEAR(x[i], want(p), 1e-9 * (1.0 + std::abs(want(p)))) << "seed " << seed << " entry " << i;
          ++p;
        }
      }
    }
  }
}

// Started at the solution, nothing is left to do: no iteration, the same x.
// Started near it, the tolerance is relative to the right-hand side without
// the guess, so a good guess needs fewer iterations than none.
TEST(PcgFixed, AWarmStartCountsAgainstTheColdResidual) {
  const System s = make_system(24, 7);
  const Eigen::VectorXd want = reduced_solution(s);
  std::vector<double> exact(s.b.size(), 0.0), near(s.b.size(), 0.0), none(s.b.size(), 0.0);
  int p = 0;
  for (std::size_t i = 0; i < exact.size(); ++i)
    if (!s.fixed[i]) exact[i] = want(p), near[i] = want(p) * (1.0 + 1e-3), ++p;
  std::vector<double> x;
  EXPECT_EQ(solve(s, exact, 1e-6, x), 0);
  p = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (s.fixed[i]) continue;
    EXPECT_NEAR(x[i], want(p), 1e-12 * (1.0 + std::abs(want(p))));
    ++p;
  }
  const long from_near = solve(s, near, 1e-6, x);
  const long from_none = solve(s, none, 1e-6, x);
  EXPECT_LT(from_near, from_none);
}

}  // namespace
}  // namespace mrf
