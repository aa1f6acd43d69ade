// Wendland C2 kernel (REFERENCE.md §5, TEST 5.1): normalisation, support,
// derivative against finite differences, odd gradient, lattice sums.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mrf/fluid/kernel.hpp"
#include "mrf/fluid/viscosity.hpp"

namespace mrf {
namespace {

constexpr double k_h = 13e-6;  // m, the paper-scene smoothing length

TEST(SphKernel, IntegratesToOneOnFineLattice) {
  // Midpoint sum of W over a lattice of spacing h/40 covering the support:
  // the continuum integral is 1 (alpha = 21/(16 pi h^3)).
  const double d = k_h / 40.0;
  const int n = 80;
  double sum = 0.0;
  for (int i = -n; i < n; ++i)
    for (int j = -n; j < n; ++j)
      for (int k = -n; k < n; ++k)
        sum += kernel_w(d * std::sqrt((i + 0.5) * (i + 0.5) + (j + 0.5) * (j + 0.5) + (k + 0.5) * (k + 0.5)), k_h);
  EXPECT_NEAR(sum * d * d * d, 1.0, 1e-6);
}

TEST(SphKernel, CompactSupportOfRadiusTwoH) {
  EXPECT_GT(kernel_w(1.999 * k_h, k_h), 0.0);
  EXPECT_LT(kernel_dwdr(1.999 * k_h, k_h), 0.0);
  EXPECT_EQ(kernel_w(2.0 * k_h, k_h), 0.0);
  EXPECT_EQ(kernel_w(2.5 * k_h, k_h), 0.0);
  EXPECT_EQ(kernel_dwdr(2.0 * k_h, k_h), 0.0);
  EXPECT_DOUBLE_EQ(kernel_w(0.0, k_h), 21.0 / (16.0 * k_pi * k_h * k_h * k_h));
}

TEST(SphKernel, DerivativeMatchesFiniteDifference) {
  for (double q : {0.1, 0.5, 1.0, 1.5, 1.9}) {
    const double r = q * k_h, e = 1e-6 * k_h;
    const double fd = (kernel_w(r + e, k_h) - kernel_w(r - e, k_h)) / (2 * e);
    EXPECT_NEAR(kernel_dwdr(r, k_h), fd, 1e-7 * std::abs(fd)) << "q = " << q;
  }
}

TEST(SphKernel, GradientIsOddAndPointsInward) {
  const Vec3 r_ab(3e-6, -5e-6, 7e-6);
  const Vec3 ga = kernel_gradient(r_ab, k_h), gb = kernel_gradient(-r_ab, k_h);
  EXPECT_LT((ga + gb).norm(), 1e-14 * ga.norm());
  EXPECT_LT(ga.dot(r_ab), 0.0);  // W decreases away from b
}

TEST(SphKernel, LatticeSumsCloseToOne) {
  // Sum V W ~ 1 for Wendland at h/dx = 1.3-2 (TEST 5.1); the residual is the
  // quadrature error that build_fluid_cell and the Morris term divide out.
  for (double ratio : {1.3, 1.5, 2.0}) {
    const double dx = k_h / ratio;
    EXPECT_NEAR(lattice_kernel_sum(dx, k_h), 1.0, 0.012) << "h/dx = " << ratio;
    EXPECT_NEAR(1.0 / morris_lattice_correction(dx, k_h), 1.0, 0.035) << "h/dx = " << ratio;
  }
  EXPECT_NEAR(lattice_kernel_sum(k_h / 1.3, k_h), 1.0095, 1e-4);
}

}  // namespace
}  // namespace mrf

namespace mrf {
namespace {
// KernelW (alpha computed once, what the pair loops call) is the law of
// kernel_w and kernel_dwdr_over_r bit for bit, inside and at the support.
TEST(SphKernel, HoistedKernelEqualsTheFreeFunctionsBitForBit) {
  for (double h : {1.3e-6, 6.5e-6, 1.95e-5}) {
    const KernelW w(h);
    for (int k = 0; k <= 2100; ++k) {
      const double r = 1e-3 * k * h;
      ASSERT_EQ(w(r), kernel_w(r, h)) << "r/h " << r / h;
      ASSERT_EQ(w.dwdr_over_r(r), kernel_dwdr_over_r(r, h)) << "r/h " << r / h;
    }
  }
}
}  // namespace
}  // namespace mrf

namespace mrf {
namespace {
// kernel_rows (the vector units' kernel of the coupling pairs) is KernelW
// bit for bit: r^2 on a fine grid from 0 past the support, the support
// itself and its neighbouring doubles, in a length that leaves a scalar
// tail; and a changed law is seen (the comparison can fail).
TEST(SphKernel, VectorRowsEqualTheScalarKernelBitForBit) {
  for (double h : {1.3e-6, 1.04e-5, 1.3e-5}) {
    const KernelW k(h);
    std::vector<double> r2;
    for (int j = 0; j <= 2203; ++j) r2.push_back(std::pow(1e-3 * j * h, 2));
    const double edge = std::pow(k_kernel_support * h, 2);
    for (double e : {std::nextafter(edge, 0.0), edge, std::nextafter(edge, 1.0)}) r2.push_back(e);
    std::vector<double> w(r2.size()), f(r2.size());
    kernel_rows(k, r2.data(), r2.size(), w.data(), f.data());
    int inside = 0;
    for (std::size_t p = 0; p < r2.size(); ++p) {
      const double r = std::sqrt(r2[p]);
      ASSERT_EQ(w[p], k(r)) << "r/h " << r / h;
      ASSERT_EQ(f[p], k.dwdr_over_r(r)) << "r/h " << r / h;
      inside += w[p] > 0;
    }
    EXPECT_GT(inside, 1900);  // most of the grid lies inside the support
    KernelW other = k;
    other.alpha *= 1.0 + 1e-15;  // a law a few ulp off differs somewhere
    kernel_rows(other, r2.data(), r2.size(), w.data(), f.data());
    bool differs = false;
    for (std::size_t p = 0; p < r2.size() && !differs; ++p) differs = w[p] != k(std::sqrt(r2[p]));
    EXPECT_TRUE(differs);
  }
}
}  // namespace
}  // namespace mrf
