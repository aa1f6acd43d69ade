#include "support/fit_order.hpp"

#include <gsl/gsl_fit.h>

#include <cmath>
#include <stdexcept>

namespace mrf::test {

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err) {
  if (h.size() != err.size() || h.size() < 3) throw std::invalid_argument("fit_order: need >= 3 points");
  std::vector<double> lx(h.size()), ly(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    lx[i] = std::log(h[i]);
    ly[i] = std::log(err[i]);
  }
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(lx.data(), 1, ly.data(), 1, lx.size(), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  return {c1, std::sqrt(cov11)};
}

Vec3 fd_gradient(const std::function<double(const Vec3&)>& energy, const Vec3& r, double eps) {
  Vec3 g;
  for (int d = 0; d < 3; ++d) {
    Vec3 a = r, b = r;
    a[d] += eps;
    b[d] -= eps;
    g[d] = (energy(a) - energy(b)) / (2 * eps);
  }
  return g;
}

}  // namespace mrf::test
