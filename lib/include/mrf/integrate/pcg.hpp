// Matrix-free preconditioned conjugate gradients, shared by the two implicit
// contact solvers (per-particle Vec3 blocks in implicit_contact.cpp, one
// double per contact in contact_dual.cpp).
#pragma once
#include <cmath>
#include <vector>

#include "mrf/vec.hpp"

namespace mrf {

inline double element_dot(double a, double b) { return a * b; }
inline double element_dot(const Vec3& a, const Vec3& b) { return a.dot(b); }
template <class T>
T zero_element();
template <>
inline double zero_element<double>() { return 0.0; }
template <>
inline Vec3 zero_element<Vec3>() { return Vec3::Zero(); }

template <class T>
double vector_dot(const std::vector<T>& u, const std::vector<T>& v) {
  double s = 0;
  for (std::size_t i = 0; i < u.size(); ++i) s += element_dot(u[i], v[i]);
  return s;
}

template <class T>
struct PcgScratch {
  std::vector<T> r, z, p, q;
};

// Solves A x = b for symmetric positive definite A from x = 0, until
// |r| <= rtol |b| or max_it iterations. apply(p, out): out = A p;
// precondition(r, z): z = M^-1 r. Returns the iterations taken.
template <class T, class Apply, class Precondition>
long pcg(const std::vector<T>& b, double rtol, long max_it, Apply&& apply, Precondition&& precondition,
         std::vector<T>& x, PcgScratch<T>& s) {
  const std::size_t n = b.size();
  x.assign(n, zero_element<T>());
  s.r = b;
  precondition(s.r, s.z);
  s.p = s.z;
  double rz = vector_dot(s.r, s.z);
  const double stop2 = rtol * rtol * vector_dot(b, b);
  long it = 0;
  while (vector_dot(s.r, s.r) > stop2 && it < max_it) {
    apply(s.p, s.q);
    const double alpha = rz / vector_dot(s.p, s.q);
    for (std::size_t a = 0; a < n; ++a) {
      x[a] += alpha * s.p[a];
      s.r[a] -= alpha * s.q[a];
    }
    precondition(s.r, s.z);
    const double rz_new = vector_dot(s.r, s.z);
    const double beta = rz_new / rz;
    rz = rz_new;
    for (std::size_t a = 0; a < n; ++a) s.p[a] = s.z[a] + beta * s.p[a];
    ++it;
  }
  return it;
}

// Solves A x = b with the entries where fixed[a] != 0 held at x0[a]: CG on
// the free block, A_FF x_F = b_F - A_FC x0_C (symmetric positive definite
// when A is), warm-started at x_F = guess_F and converged until the free
// residual is below rtol times that of x_F = 0. apply and precondition as
// for pcg, over the whole vector (the fixed entries of their results are
// ignored). x: x0 on the fixed entries. Returns the CG iterations.
template <class Apply, class Precondition>
long pcg_fixed(const std::vector<double>& b, const std::vector<char>& fixed, const std::vector<double>& x0,
               const std::vector<double>& guess, double rtol, long max_it, Apply&& apply,
               Precondition&& precondition, std::vector<double>& x, PcgScratch<double>& s) {
  const std::size_t n = b.size();
  auto masked = [&](std::vector<double>& v) {
    for (std::size_t a = 0; a < n; ++a)
      if (fixed[a]) v[a] = 0.0;
  };
  // the right-hand side with the fixed entries moved over, then less the guess
  std::vector<double> xs(n, 0.0), q, rhs(n);
  for (std::size_t a = 0; a < n; ++a)
    if (fixed[a]) xs[a] = x0[a];
  apply(xs, q);
  for (std::size_t a = 0; a < n; ++a) rhs[a] = fixed[a] ? 0.0 : b[a] - q[a];
  const double base = vector_dot(rhs, rhs);
  for (std::size_t a = 0; a < n; ++a) xs[a] = fixed[a] ? 0.0 : guess[a];
  apply(xs, q);
  for (std::size_t a = 0; a < n; ++a) rhs[a] = fixed[a] ? 0.0 : rhs[a] - q[a];
  const double left = vector_dot(rhs, rhs);
  long it = 0;
  std::vector<double> dx;
  if (left > 0 && left > rtol * rtol * base)
    it = pcg(
        rhs, rtol * std::sqrt(base / left), max_it,
        [&](const std::vector<double>& p, std::vector<double>& out) {
          apply(p, out);
          masked(out);
        },
        [&](const std::vector<double>& r, std::vector<double>& z) {
          precondition(r, z);
          masked(z);
        },
        dx, s);
  x.resize(n);
  for (std::size_t a = 0; a < n; ++a) x[a] = fixed[a] ? x0[a] : xs[a] + (dx.empty() ? 0.0 : dx[a]);
  return it;
}

}  // namespace mrf
