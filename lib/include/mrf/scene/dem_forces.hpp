// Pair forces of the DEM scene (dipole + Hertz between free particles, Hertz
// between free and wall spheres) and the sums the stress observables need.
// OpenMP over the half pair lists with one force buffer per thread, reduced
// in thread order: bitwise reproducible for a fixed thread count.
#pragma once
#include <array>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/state.hpp"

namespace mrf {

struct PairSums {
  std::array<double, 2> wall_fz{0, 0};  // z-force of the particles on the lower [0] / upper [1] wall (N)
  double virial_mag_xz = 0;             // sum over pairs of r_ik,x F_ik,z, dipole part (N m)
  double virial_con_xz = 0;             // same, Hertz part (N m)
  double max_overlap = 0;               // m
  double energy_dipole = 0;             // J (within the cutoff, unshifted)
  double energy_hertz = 0;              // J
  long pair_evaluations = 0;            // pairs in the lists visited

  void merge(const PairSums& o);
};

// Per-thread force buffers, kept between steps so the hot loop does not allocate.
struct ForceBuffers {
  std::vector<std::vector<Vec3>> f;
  std::vector<PairSums> sums;
};

// Overwrites free.f with the pair forces and returns the sums.
PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf);
PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists);

}  // namespace mrf
