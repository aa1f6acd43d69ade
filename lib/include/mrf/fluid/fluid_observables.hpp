// Observables of the SPH carrier fluid: wall forces and shear stress,
// velocity profile, density error, mass, momentum, Reynolds number.
// All read the consistent state kept by refresh() (fluid_cell.hpp).
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "mrf/fluid/fluid_cell.hpp"

namespace mrf {

// Force (N) that the lower [0] and upper [1] wall particles exert on the
// fluid: pressure and Morris viscous terms of all fluid-wall pairs.
std::array<Vec3, 2> wall_force_on_fluid(const FluidCell& c);

// Shear stress (Pa) of DESIGN.md: z-force per wall area the walls exert on
// the fluid, signs made consistent so that both are positive for a
// dissipative fluid (the upper wall moves +z and pulls the fluid along +z).
// A Newtonian fluid in steady Couette flow gives tau = eta gdot.
struct FluidWallStress {
  double lower;  // -F_lower,z / A
  double upper;  // +F_upper,z / A
  double tau;    // (lower + upper) / 2
};
FluidWallStress wall_shear_stress(const FluidCell& c);

// Mean v_z in `nbins` equal slabs across the gap (x from -gap/2 to gap/2).
struct ProfileBin {
  double x;      // slab centre (m)
  double vz;     // mean flow velocity (m/s); 0 for an empty slab
  int count;     // particles in the slab
};
std::vector<ProfileBin> velocity_profile(const FluidCell& c, int nbins);

// Relative L2 error of the fluid particles' v_z against exact(x) (m/s):
// sqrt(sum (v_z - u)^2 / sum u^2) over all fluid particles.
double profile_error(const FluidCell& c, const std::function<double(double)>& exact);

// Relative density error: mean of |rho/rho0 - 1| and its maximum.
struct DensityStats {
  double mean_abs_error;
  double max_abs_error;
};
DensityStats density_stats(const FluidCell& c);

// The fluid's first layer at the walls: fluid particles within one lattice
// spacing of either wall plane, over the count the starting lattice puts
// there (2 ly lz / dx^2). 1 on the lattice; below 1 when the layer next to the
// walls has receded into the bulk (docs/study.md, "The carrier's wall layer").
double wall_layer_fraction(const FluidCell& c);

double total_mass(const FluidCell& c);      // kg
Vec3 total_momentum(const FluidCell& c);    // kg m/s

// Channel Reynolds number V0 gap / nu with V0 = max(gdot gap, f gap^2/(8 nu))
// (= rho gdot gap^2 / eta for Couette, REFERENCE §8).
double reynolds_number(const FluidParams& p, const Box& box);

}  // namespace mrf
