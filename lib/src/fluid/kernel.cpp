#include "mrf/fluid/kernel.hpp"

#include <cmath>

namespace mrf {

double lattice_kernel_sum(double dx, double h) {
  const int n = static_cast<int>(std::ceil(k_kernel_support * h / dx));
  double sum = 0.0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) sum += kernel_w(dx * std::sqrt(double(i * i + j * j + k * k)), h);
  return dx * dx * dx * sum;
}

}  // namespace mrf
