// The pair laws that both the scalar loops and the vectorised kernel run,
// written once for any arithmetic type T: double, or a SIMD vector whose
// lanes are pairs. num(v) makes the constant v a T.
//
// No include guard, on purpose: mrf/forces/generic_laws.hpp includes this
// file inside namespace mrf (the scalar laws), and scene/pair_kernel_simd.cpp
// inside each of Highway's per-target namespaces, so that the vector
// instantiations are compiled with that target's instruction set (a template
// defined outside the target region could not inline its intrinsics).
// Templates only, and no #include.

// Dipole force of equal moments along +x (REFERENCE.md Eq. 3): sets
// (fx, fy, fz) to the force on i (N) at separation (dx, dy, dz) with
// 1/r = inv_r; returns (1 - 3c^2)/r^3 (1/m^3).
template <class T, class Num>
inline T dipole_x_law(T pref, T dx, T dy, T dz, T inv_r, T& fx, T& fy, T& fz, Num num) {
  // Grouped for a short dependency chain (the vector kernel is bound by
  // its latency): w and 2 w dx do not wait for c^2.
  const T inv_r2 = inv_r * inv_r;
  const T c = dx * inv_r, c2 = c * c;
  const T w = (pref * inv_r) * (inv_r2 * inv_r2);  // pref / r^5
  const T a = w * (num(1.0) - num(5.0) * c2);      // radial part / r
  fx = a * dx + (num(2.0) * dx) * w;               // + 2 pref c / r^4 along x
  fy = a * dy;
  fz = a * dz;
  return (num(1.0) - num(3.0) * c2) * inv_r2 * inv_r;
}

// Hertz (REFERENCE.md Eq. 2): force k h^{3/2} and energy (2/5) k h^{5/2}
// at overlap h >= 0.
template <class T, class Num, class Sqrt>
inline void hertz_law_t(T overlap, T k, T& force, T& energy, Num num, Sqrt sqrt_of) {
  const T sh = sqrt_of(overlap);
  force = k * overlap * sh;
  energy = num(0.4) * k * overlap * overlap * sh;
}

// The shifted-force form of the same law for energy minimisation
// (quasistatic/shifted_dipole.hpp, where it is derived): the radial factor
// r^-3 becomes phi_sf = r^-3 - r_c^-3 + 3 (r - r_c) r_c^-4, so energy and
// force vanish continuously at r_c. For r < r_c only (the caller cuts);
// r = 1/inv_r, inv_rc = 1/r_c. Returns (1 - 3c^2) phi_sf (1/m^3).
template <class T, class Num>
inline T dipole_x_shifted_law(T pref, T cutoff, T inv_rc, T dx, T dy, T dz, T inv_r, T r, T& fx, T& fy, T& fz,
                              Num num) {
  const T inv_r2 = inv_r * inv_r, inv_r4 = inv_r2 * inv_r2;
  const T inv_rc3 = inv_rc * inv_rc * inv_rc, inv_rc4 = inv_rc3 * inv_rc;
  const T c = dx * inv_r, c2 = c * c;
  const T phi = inv_r2 * inv_r - inv_rc3 + num(3.0) * (r - cutoff) * inv_rc4;
  const T radial = pref * ((num(1.0) - num(3.0) * c2) * (inv_r4 - inv_rc4) - num(2.0) * c2 * phi * inv_r);
  const T a = radial * inv_r;                      // radial part / r, multiplies r_ik
  const T b = num(2.0) * pref * c * phi * inv_r;   // along x^
  fx = a * dx + b;
  fy = a * dy;
  fz = a * dz;
  return (num(1.0) - num(3.0) * c2) * phi;
}
