// One-way Stokes drag toward an imposed Couette profile, REFERENCE.md §3.
#pragma once
#include <cmath>

#include "mrf/vec.hpp"

namespace mrf {

// Stokes friction coefficient gamma = 6 pi eta R (kg/s).
inline double stokes_gamma(double viscosity, double radius) { return 6.0 * k_pi * viscosity * radius; }

// Imposed linear Couette profile u = (0, 0, gdot x) (m/s); walls at x = -+gap/2.
inline Vec3 couette_velocity(const Vec3& x, double shear_rate) { return Vec3(0, 0, shear_rate * x.x()); }

// The one law of the wall motion: the wall planes x = side gap/2 (side -1
// lower, +1 upper) move rigidly with the Couette profile there, and with
// them the DEM wall spheres (integrate/steps.hpp) and the SPH wall particles
// (fluid/fluid_cell.hpp). Their speed |gdot| gap / 2 (m/s) bounds steps and
// list skins.
inline Vec3 wall_velocity(int side, double shear_rate, double gap) {
  return couette_velocity(Vec3(side * 0.5 * gap, 0, 0), shear_rate);
}
inline double wall_speed(double shear_rate, double gap) { return std::abs(shear_rate) * 0.5 * gap; }

// F = gamma (u - v) (N).
inline Vec3 stokes_drag(const Vec3& v, const Vec3& u, double gamma) { return gamma * (u - v); }

// Relaxation time tau_p = m/gamma (s).
inline double relaxation_time(double mass, double gamma) { return mass / gamma; }

}  // namespace mrf
