// Helpers shared by the verification suites.
#pragma once
#include <functional>
#include <vector>

#include "mrf/vec.hpp"

namespace mrf::test {

// Least-squares fit of log(err) = c + p log(h) with GSL; returns the slope p
// (the observed order) and its standard error.
struct OrderFit {
  double order;
  double stderr_order;
};
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err);

// Central-difference gradient of a scalar field at r with step `eps` (m).
Vec3 fd_gradient(const std::function<double(const Vec3&)>& energy, const Vec3& r, double eps);

}  // namespace mrf::test
