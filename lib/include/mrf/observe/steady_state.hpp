// Steady-state detection: how much of the start of a series is still
// transient, by the MSER-5 rule (White 1997; White, Cobb & Spratt 2000).
// The series is cut into batches of 5 samples; for every candidate cut d
// (in batches, up to half the series) the marginal standard error
//   MSER(d) = sum_{j>=d} (b_j - mean_{>=d})^2 / (k - d)^2
// is computed over the k batch means b_j, and the cut with the smallest value
// is the truncation point: the start of the steady part.
#pragma once
#include <cstddef>
#include <vector>

namespace mrf {

// Number of leading samples MSER-5 would discard (a multiple of `batch`);
// 0 for series shorter than 4 batches.
std::size_t mser_truncation(const std::vector<double>& series, std::size_t batch = 5);

}  // namespace mrf
