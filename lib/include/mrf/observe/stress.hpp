// Shear-stress observables (REFERENCE.md §7, DESIGN.md conventions).
// tau > 0 for a dissipative suspension; axes x gradient, z flow.
#pragma once
#include <array>

#include "mrf/box.hpp"

namespace mrf {

// Wall method: the z-force per area the walls must exert to keep moving,
// averaged over both walls. `wall_fz` is the z-force that the particles (or
// fluid) exert on the lower [0] and upper [1] wall. The upper wall moves
// +z, so it must push with -F_upper; the lower one with +F_lower.
inline double wall_shear_stress(const std::array<double, 2>& wall_fz, const Box& box) {
  return 0.5 * (wall_fz[0] - wall_fz[1]) / box.wall_area();
}

// Virial (Irving-Kirkwood) shear stress of pair forces:
// sigma_xz = -(1/V) sum_pairs r_ik,x F_ik,z, V = gap ly lz.
inline double virial_shear_stress(double virial_xz, const Box& box) { return -virial_xz / box.volume(); }

// Carrier contribution of the imposed linear profile (model 1): eta gdot.
inline double imposed_fluid_stress(double viscosity, double shear_rate) { return viscosity * shear_rate; }

}  // namespace mrf
