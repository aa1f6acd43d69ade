// Matrix-free preconditioned conjugate gradients, shared by the two implicit
// contact solvers (per-particle Vec3 blocks in implicit_contact.cpp, one
// double per contact in contact_dual.cpp).
#pragma once
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

}  // namespace mrf
