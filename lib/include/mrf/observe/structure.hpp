// Gap-spanning clusters, a structure indicator one model-1 run can report
// (issue 14's candidate indicators): free spheres are joined when their
// centres are closer than 2R + touch R (touching, or within touch R of it),
// and a cluster touches a wall when one of its spheres is that close to a
// wall sphere. A cluster touching both walls spans the gap and carries
// stress from wall to wall; one touching a single wall, or none, leaves its
// share to the fluid around it, which model 1 imposes and the two-way models
// return to the walls (the self-consistency mismatch of study/criterion.hpp).
#pragma once
#include <cstddef>

#include "mrf/scene/shear_cell.hpp"

namespace mrf {

inline constexpr double k_cluster_touch = 0.02;  // gap allowance, in radii

struct ClusterStats {
  double spanning_fraction = 0;  // free spheres in clusters touching both walls, over all free spheres
  double wall_fraction = 0;      // in clusters touching at least one wall
  double largest_fraction = 0;   // in the largest cluster
  std::size_t clusters = 0;      // clusters, isolated spheres included
};

// Minimum image in y and z; O(N) with a cell grid.
ClusterStats cluster_stats(const ShearCell& cell, double radius, double touch = k_cluster_touch);

}  // namespace mrf
