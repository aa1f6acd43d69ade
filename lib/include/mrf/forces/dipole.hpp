// Fixed point dipoles, REFERENCE.md §1 (paper Eq. 3). Pure functions, SI.
// Pair convention: r_ik = r_i - r_k, the functions return the force on i.
#pragma once
#include "mrf/forces/generic_laws.hpp"
#include "mrf/vec.hpp"

namespace mrf {

// Dipole moment (A m^2) of a sphere of radius r (m) with magnetisation M (A/m).
inline double dipole_moment(double radius, double magnetization) {
  return magnetization * sphere_volume(radius);
}

// U = (mu0 / 4 pi r^3) [m_i.m_k - 3 (m_i.r^)(m_k.r^)]  (J)
inline double dipole_energy(const Vec3& r_ik, const Vec3& m_i, const Vec3& m_k) {
  const double r2 = r_ik.squaredNorm();
  const double r = std::sqrt(r2);
  const Vec3 n = r_ik / r;
  return k_mu0 / (4.0 * k_pi * r2 * r) * (m_i.dot(m_k) - 3.0 * m_i.dot(n) * m_k.dot(n));
}

// F = (3 mu0 / 4 pi r^4) [(m_i.r^) m_k + (m_k.r^) m_i + (m_i.m_k) r^ - 5 (m_i.r^)(m_k.r^) r^]
inline Vec3 dipole_force(const Vec3& r_ik, const Vec3& m_i, const Vec3& m_k) {
  const double r2 = r_ik.squaredNorm();
  const Vec3 n = r_ik / std::sqrt(r2);
  const double a = m_i.dot(n), b = m_k.dot(n);
  return 3.0 * k_mu0 / (4.0 * k_pi * r2 * r2) * (a * m_k + b * m_i + m_i.dot(m_k) * n - 5.0 * a * b * n);
}

// Equal moments m along +x (the shear-cell case), c = cos(theta) = r^.x:
// F = (3 mu0 m^2 / 4 pi r^4) [(1 - 5c^2) r^ + 2c x^]. `pref` = 3 mu0 m^2 / (4 pi).
inline double dipole_prefactor(double moment) { return 3.0 * k_mu0 * moment * moment / (4.0 * k_pi); }

// Pair evaluator of this law in the HOOMD style (STYLE.md §1), the one place
// it is written: the loop supplies r_ik = (dx, dy, dz) (m) and the 1/r it
// has already computed, and keeps the cut-off, +-F, virial and sums. The energy
// U = (mu0 m^2 / 4 pi r^3)(1 - 3c^2) = (pref/3)(1 - 3c^2)/r^3 comes back
// without its constant factor, so a loop sums (1 - 3c^2)/r^3 and scales once.
struct DipoleX {
  double pref;  // 3 mu0 m^2 / (4 pi) (N m^4)

  // Sets f to the force on i (N); returns (1 - 3c^2)/r^3 (1/m^3).
  double eval(double dx, double dy, double dz, double inv_r, Vec3& f) const {
    return dipole_x_law(pref, dx, dy, dz, inv_r, f.x(), f.y(), f.z(), [](double v) { return v; });
  }
  // J m^3: turns a sum of eval() returns into an energy.
  double energy_scale() const { return pref / 3.0; }
};

inline Vec3 dipole_force_x(const Vec3& r_ik, double pref) {
  Vec3 f;
  DipoleX{pref}.eval(r_ik.x(), r_ik.y(), r_ik.z(), 1.0 / r_ik.norm(), f);
  return f;
}

// Energy (J) of the equal-moment pair: the same evaluator, scaled.
inline double dipole_energy_x(const Vec3& r_ik, double pref) {
  const DipoleX law{pref};
  Vec3 f;
  return law.energy_scale() * law.eval(r_ik.x(), r_ik.y(), r_ik.z(), 1.0 / r_ik.norm(), f);
}

// Head-to-tail force magnitude at contact (r = 2R): (pi/6) mu0 R^2 M^2 (N).
inline double dipole_contact_force(double radius, double magnetization) {
  return k_pi / 6.0 * k_mu0 * radius * radius * magnetization * magnetization;
}

}  // namespace mrf
