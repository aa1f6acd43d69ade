// MSER-5 truncation on series with a known transient.
#include "mrf/observe/steady_state.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>

namespace mrf {
namespace {

std::vector<double> series(std::size_t n, std::size_t transient, double jump, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = g(rng) + (i < transient ? jump * (1.0 - double(i) / double(transient)) : 0.0);
  return y;
}

TEST(SteadyState, StationaryNoiseIsBarelyTruncated) {
  // over many stationary series the median cut is a small part of the series
  std::vector<std::size_t> cuts;
  for (unsigned s = 0; s < 41; ++s) cuts.push_back(mser_truncation(series(1000, 0, 0.0, s)));
  std::sort(cuts.begin(), cuts.end());
  EXPECT_LT(cuts[20], 100u);
}

TEST(SteadyState, LinearTransientIsFoundNearItsEnd) {
  for (unsigned s = 0; s < 10; ++s) {
    const std::size_t cut = mser_truncation(series(1000, 300, 20.0, s));
    EXPECT_GT(cut, 200u) << s;  // most of the ramp is discarded
    EXPECT_LT(cut, 400u) << s;  // and not much of the steady part
  }
}

TEST(SteadyState, StepTransientIsCutAtTheStep) {
  std::vector<double> y(500, 1.0);
  for (std::size_t i = 0; i < 150; ++i) y[i] = 5.0;
  for (std::size_t i = 0; i < y.size(); ++i) y[i] += 1e-3 * std::sin(0.7 * double(i));
  EXPECT_EQ(mser_truncation(y), 150u);
  EXPECT_EQ(mser_truncation(std::vector<double>(12, 1.0)), 0u);  // shorter than 4 batches
}

}  // namespace
}  // namespace mrf
