// SPH smoothing kernel: Wendland C2 in 3D (REFERENCE.md §5, Wendland 1995).
//
// Why Wendland C2 and not the cubic spline: its Fourier transform is
// positive, so it has no pairing (clumping) instability; particles keep an
// ordered arrangement over the long, viscosity-dominated runs of the shear
// cell, and the summation density stays within the 1 % budget. It is C2 at
// the support edge, and its lattice sum is close to 1 for h/dx = 1.3-2.
//
// W(r, h) = alpha (1 - q/2)^4 (2q + 1), q = r/h < 2, alpha = 21 / (16 pi h^3);
// dW/dr = -5 alpha q (1 - q/2)^3 / h. Units: W in 1/m^3, dW/dr in 1/m^4.
// Gradient convention: grad_a W_ab = r_ab (dW/dr)/r with r_ab = x_a - x_b,
// so grad_a W_ab = -grad_b W_ab (odd in r_ab).
#pragma once
#include <cstddef>

#include "mrf/vec.hpp"

namespace mrf {

// Kernel support radius in units of h.
inline constexpr double k_kernel_support = 2.0;

inline double kernel_alpha(double h) { return 21.0 / (16.0 * k_pi * h * h * h); }

// W(r) of one smoothing length h with alpha computed once: what loops over
// many pairs call; kernel_w below is the same law, bit for bit.
struct KernelW {
  double h, alpha;
  explicit KernelW(double h_) : h(h_), alpha(kernel_alpha(h_)) {}
  double operator()(double r) const {
    const double q = r / h;
    if (q >= k_kernel_support) return 0.0;
    const double t = 1.0 - 0.5 * q;
    return alpha * t * t * t * t * (2.0 * q + 1.0);
  }
  // (dW/dr)/r, the same law as kernel_dwdr_over_r below, bit for bit
  double dwdr_over_r(double r) const {
    const double q = r / h;
    if (q >= k_kernel_support) return 0.0;
    const double t = 1.0 - 0.5 * q;
    return -5.0 * alpha * t * t * t / (h * h);
  }
};

// W and (dW/dr)/r at r = sqrt(r2[p]) for n squared distances (m^2), into
// w[p] and dwdr_over_r[p]: KernelW's expressions on the vector units (one
// binary, the best instruction set of the machine, fluid/kernel_simd.cpp),
// equal to KernelW bit for bit (sqrt and division are correctly rounded in
// every lane, the products keep their order and stay unfused).
void kernel_rows(const KernelW& k, const double* r2, std::size_t n, double* w, double* dwdr_over_r);

// W(r, h) in 1/m^3; zero for r >= 2h.
inline double kernel_w(double r, double h) { return KernelW(h)(r); }

// (dW/dr)/r in 1/m^5: finite at r = 0, the factor that multiplies r_ab in
// the gradient and in the Morris viscous term.
inline double kernel_dwdr_over_r(double r, double h) {
  const double q = r / h;
  if (q >= k_kernel_support) return 0.0;
  const double t = 1.0 - 0.5 * q;
  return -5.0 * kernel_alpha(h) * t * t * t / (h * h);
}

// dW/dr in 1/m^4 (<= 0).
inline double kernel_dwdr(double r, double h) { return r * kernel_dwdr_over_r(r, h); }

// grad_a W_ab for separation r_ab = x_a - x_b (1/m^4).
inline Vec3 kernel_gradient(const Vec3& r_ab, double h) {
  return kernel_dwdr_over_r(r_ab.norm(), h) * r_ab;
}

// S1 = dx^3 sum_b W(|x_b|, h) over an infinite simple cubic lattice of
// spacing dx around one of its points (itself included), dimensionless; the
// quadrature of the kernel integral (1 in the continuum): 1.0095 at
// h/dx = 1.3. build_fluid_cell divides the summation density by it.
double lattice_kernel_sum(double dx, double h);

}  // namespace mrf
