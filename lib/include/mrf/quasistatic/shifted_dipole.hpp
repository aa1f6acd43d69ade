// Shifted-force dipole law for energy minimisation (REFERENCE.md §1,
// "Truncation"). The truncated law of forces/dipole.hpp jumps in energy and
// force at the cut-off r_c; a minimiser that sees a particle cross r_c sees a
// step in the energy landscape, and FIRE's power test (F.v) then misjudges
// the descent. This form is continuous in energy and force at r_c.
//
// Equal moments m along +x, c = cos(theta) = r^.x, U = A(r^) phi(r) with
// A = (mu0 m^2 / 4 pi)(1 - 3c^2) = (pref/3)(1 - 3c^2), phi = r^-3. The shifted
// form keeps the angular factor and shifts the radial one,
//   phi_sf(r) = r^-3 - r_c^-3 + 3 (r - r_c) r_c^-4      (r < r_c; 0 beyond),
// so phi_sf(r_c) = phi_sf'(r_c) = 0 and the whole gradient of U_sf vanishes
// at r_c. F = -grad U_sf = -A phi_sf' r^ - phi_sf grad A, grad A = -2 pref c (x^ - c r^)/r:
//   F = pref [ (1 - 3c^2)(r^-4 - r_c^-4) - 2 c^2 phi_sf / r ] r^ + 2 pref c (phi_sf / r) x^.
// As r_c -> inf this is the law of forces/dipole.hpp; well inside r_c the
// two differ by the shift terms, O(pref r_c^-4) radially and
// O(pref r_c^-3 / r) in the angular part. The second derivative jumps at r_c.
#pragma once
#include <cmath>

#include "mrf/forces/generic_laws.hpp"
#include "mrf/vec.hpp"

namespace mrf {

// Pair evaluator with the interface of DipoleX (forces/dipole.hpp), so the
// pair loops of scene/dem_forces.hpp run it unchanged; its law is
// dipole_x_shifted_law of forces/laws-inl.h, which the vector kernel runs too.
struct DipoleXShiftedForce {
  double pref;    // 3 mu0 m^2 / (4 pi) (N m^4)
  double cutoff;  // r_c (m)
  double inv_rc;  // 1 / r_c (1/m)

  // Sets f to the force on i (N) for r_ik = (dx, dy, dz) (m) with 1/r given;
  // returns U_sf / energy_scale() = (1 - 3c^2) phi_sf (1/m^3). Zero at and
  // beyond r_c.
  double eval(double dx, double dy, double dz, double inv_r, Vec3& f) const {
    const double r = 1.0 / inv_r;
    if (!(r < cutoff)) {
      f = Vec3::Zero();
      return 0.0;
    }
    return dipole_x_shifted_law(pref, cutoff, inv_rc, dx, dy, dz, inv_r, r, f.x(), f.y(), f.z(),
                                [](double v) { return v; });
  }
  // J m^3: turns a sum of eval() returns into an energy.
  double energy_scale() const { return pref / 3.0; }
};

inline DipoleXShiftedForce shifted_dipole_x(double pref, double cutoff) { return {pref, cutoff, 1.0 / cutoff}; }

// Force on i (N) of the shifted-force law, r_ik = r_i - r_k (m).
inline Vec3 shifted_dipole_force_x(const Vec3& r_ik, double pref, double cutoff) {
  Vec3 f;
  shifted_dipole_x(pref, cutoff).eval(r_ik.x(), r_ik.y(), r_ik.z(), 1.0 / r_ik.norm(), f);
  return f;
}

// Pair energy (J) of the shifted-force law.
inline double shifted_dipole_energy_x(const Vec3& r_ik, double pref, double cutoff) {
  const DipoleXShiftedForce law = shifted_dipole_x(pref, cutoff);
  Vec3 f;
  return law.energy_scale() * law.eval(r_ik.x(), r_ik.y(), r_ik.z(), 1.0 / r_ik.norm(), f);
}

}  // namespace mrf
