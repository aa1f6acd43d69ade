// Export of a shear-cell configuration to LAMMPS, so that the peer code runs
// the identical scene (benchmarks/peers/lammps/).
#pragma once
#include <string>

#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

// LAMMPS data file, atom_style hybrid sphere dipole, SI units: type 1 free
// magnetic spheres (moment along +x, velocity of the Couette profile), type 2
// wall spheres (non-magnetic, velocity of their wall). Box: x non-periodic
// with room for the walls, y and z periodic.
void write_lammps_data(const ShearCell& cell, const DemParams& p, const std::string& path);

// LAMMPS include file with the scene's derived parameters as variables
// (SI): radius, mass, moment, gamma, hertz_k, hertz_kn (= k / sqrt(R_eff),
// LAMMPS' Hertz convention), dipole_cutoff, skin, shear_rate, gap,
// wall_speed, tau_p, and mrf's automatic dt.
void write_lammps_params(const DemParams& p, const Box& box, double dt, const std::string& path);

}  // namespace mrf
