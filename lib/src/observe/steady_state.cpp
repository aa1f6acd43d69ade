#include "mrf/observe/steady_state.hpp"

namespace mrf {

std::size_t mser_truncation(const std::vector<double>& series, std::size_t batch) {
  if (batch == 0) batch = 1;
  const std::size_t k = series.size() / batch;
  if (k < 4) return 0;
  std::vector<double> b(k, 0.0);
  for (std::size_t j = 0; j < k; ++j) {
    for (std::size_t i = 0; i < batch; ++i) b[j] += series[j * batch + i];
    b[j] /= static_cast<double>(batch);
  }
  // suffix sums give every tail's mean and sum of squares in one pass
  std::vector<double> s1(k + 1, 0.0), s2(k + 1, 0.0);
  for (std::size_t j = k; j-- > 0;) {
    s1[j] = s1[j + 1] + b[j];
    s2[j] = s2[j + 1] + b[j] * b[j];
  }
  std::size_t best = 0;
  double best_value = 0;
  for (std::size_t d = 0; d <= k / 2; ++d) {
    const double n = static_cast<double>(k - d);
    const double ss = s2[d] - s1[d] * s1[d] / n;  // sum of squared deviations of the tail
    const double value = ss / (n * n);
    if (d == 0 || value < best_value) {
      best_value = value;
      best = d;
    }
  }
  return best * batch;
}

}  // namespace mrf
