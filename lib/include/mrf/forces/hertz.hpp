// Hertz normal contact, REFERENCE.md §2 (paper Eq. 2). Pure functions, SI units.
#pragma once
#include <cmath>

#include "mrf/forces/generic_laws.hpp"
#include "mrf/vec.hpp"

namespace mrf {

// Hertz prefactor k (N/m^1.5) of F = k h^{3/2} for two spheres of the same
// material: k = (4/3) E* sqrt(R*), 1/E* = 2(1-nu^2)/Y, R* = Ri Rk/(Ri+Rk).
inline double hertz_stiffness(double youngs_modulus, double poisson_ratio, double r_i, double r_k) {
  const double e_star = youngs_modulus / (2.0 * (1.0 - poisson_ratio * poisson_ratio));
  const double r_star = r_i * r_k / (r_i + r_k);
  return 4.0 / 3.0 * e_star * std::sqrt(r_star);
}

// The law itself, the one place it is written: at overlap h > 0 (m) the
// repulsive force k h^{3/2} (N) and the stored energy (2/5) k h^{5/2} (J),
// REFERENCE.md Eq. 2. One sqrt serves both, since the pair loop needs both.
struct HertzValue {
  double force;   // N
  double energy;  // J
};
inline HertzValue hertz_law(double overlap, double k) {
  HertzValue v;
  hertz_law_t(overlap, k, v.force, v.energy, [](double x) { return x; }, [](double x) { return std::sqrt(x); });
  return v;
}

// Magnitude of the repulsive force (N) at overlap h (m); zero without overlap.
inline double hertz_force(double overlap, double k) { return overlap > 0 ? hertz_law(overlap, k).force : 0.0; }

// Elastic energy (J) stored at overlap h: (2/5) k h^{5/2}.
inline double hertz_energy(double overlap, double k) { return overlap > 0 ? hertz_law(overlap, k).energy : 0.0; }

// Local stiffness dF/dh (N/m) at overlap h: (3/2) k h^{1/2}.
inline double hertz_local_stiffness(double overlap, double k) {
  return overlap > 0 ? 1.5 * k * std::sqrt(overlap) : 0.0;
}

// Static overlap (m) under a compressive load F (N): h = (F/k)^{2/3}.
inline double hertz_overlap_under_load(double load, double k) { return std::cbrt(load * load / (k * k)); }

// Head-on elastic impact (REFERENCE TEST 2.1): maximum overlap and contact
// duration for reduced mass m* (kg) and approach speed v0 (m/s).
inline double hertz_max_overlap(double reduced_mass, double v0, double k) {
  return std::pow(1.25 * reduced_mass * v0 * v0 / k, 0.4);
}
// t_c = 2 (h_max/v0) * int_0^1 (1 - x^{5/2})^{-1/2} dx = 2.94328 h_max / v0.
inline double hertz_contact_time(double reduced_mass, double v0, double k) {
  constexpr double k_two_integral = 2.0 * 1.4716376;
  return k_two_integral * hertz_max_overlap(reduced_mass, v0, k) / v0;
}

// One Hertz contact as a pair loop sees it.
struct HertzContact {
  double f_over_r;  // |F| / r (N/m): the force on i is f_over_r * r_ik
  double energy;    // J
  double overlap;   // h (m)
};

// Pair evaluator in the HOOMD style (STYLE.md §1): the loop supplies what it
// already has, r^2 = |r_ik|^2 (m^2) and 1/r (1/m), and keeps the minimum
// image, the +-F, the virial and the sums; the evaluator holds the physics.
// The force is central, so it needs no components.
struct HertzPair {
  double k;          // Hertz prefactor (N/m^1.5)
  double sum_radii;  // contact distance R_i + R_k (m)

  // False without overlap (c untouched). r = r^2 * (1/r): no second sqrt.
  bool eval(double r2, double inv_r, HertzContact& c) const {
    const double h = sum_radii - r2 * inv_r;
    if (!(h > 0)) return false;
    const HertzValue law = hertz_law(h, k);
    c = {law.force * inv_r, law.energy, h};
    return true;
  }
};

// Force on i from a sphere pair with separation r_ik = r_i - r_k (minimum
// image) and contact distance `sum_radii` (m): the pair loop's evaluator.
inline Vec3 hertz_pair_force(const Vec3& r_ik, double sum_radii, double k) {
  const double r2 = r_ik.squaredNorm();
  HertzContact c;
  return HertzPair{k, sum_radii}.eval(r2, 1.0 / std::sqrt(r2), c) ? Vec3(c.f_over_r * r_ik) : Vec3::Zero();
}

}  // namespace mrf
