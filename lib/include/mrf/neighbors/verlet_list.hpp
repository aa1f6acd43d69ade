// Verlet pair lists with a skin for the DEM scene: free-free pairs within the
// largest free-free interaction range and free-wall pairs within contact
// range, each plus the skin. Rebuilt only when some particle may have moved
// half a skin relative to a partner.
#pragma once
#include <vector>

#include "mrf/neighbors/cell_list.hpp"
#include "mrf/state.hpp"

namespace mrf {

struct DemPairLists {
  double ff_range = 0;          // free-free interaction range without skin (m)
  double fw_range = 0;          // free-wall interaction range without skin (m); 0 = no walls
  double skin = 0;              // m
  std::vector<IndexPair> ff;    // (i, k) free-free, i < k
  std::vector<IndexPair> fw;    // (i free, k wall)
  std::vector<Vec3> x_ref;      // free positions at the last build
  double wall_travel = 0;       // largest wall displacement since the last build (m)
  long builds = 0;
};

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin);

void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box);

// True when the largest free displacement plus the largest displacement of
// any partner (free or wall) since the last build may exceed the skin.
bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box);

}  // namespace mrf
