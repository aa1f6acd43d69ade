// Verlet pair lists with a skin for the DEM scene: free-free pairs within the
// largest free-free interaction range and free-wall pairs within contact
// range, each plus the skin. The two lists are rebuilt on separate criteria:
// free-free when twice the largest free displacement since its build exceeds
// the skin; free-wall when the largest free displacement plus the wall travel
// since its build exceeds the skin.
#pragma once
#include <vector>

#include "mrf/neighbors/cell_list.hpp"
#include "mrf/state.hpp"

namespace mrf {

struct DemPairLists {
  double ff_range = 0;          // free-free interaction range without skin (m)
  double fw_range = 0;          // free-wall interaction range without skin (m); 0 = no walls
  double skin = 0;              // m
  PairRows ff;                  // free-free, row i holds the partners k > i
  std::vector<IndexPair> fw;    // (i free, k wall), sorted by i
  std::vector<Vec3> x_ref;      // free positions at the last free-free build
  std::vector<Vec3> x_ref_fw;   // free positions at the last free-wall build
  std::size_t walls_ref = 0;    // number of wall particles at the last free-wall build
  double wall_travel = 0;       // largest wall displacement since the last free-wall build (m)
  long builds = 0;              // builds of either list
  // Checkpoints: the lists as built (their reference positions decide the
  // next rebuild, their order the round-off); the ranges and skin come from
  // the scene. One field list for both directions (io/archive.hpp).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.ff.start, s.ff.k, s.fw, s.x_ref, s.x_ref_fw, s.walls_ref, s.wall_travel, s.builds);
  }
};

// Largest displacement (m) of the points x from `ref` (minimum image).
double max_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box);

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin);

// Rebuilds the lists that may be stale (both on the first call, or when the
// number of particles changed); a list whose criterion still holds is kept.
void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box);
// Rebuilds both lists unconditionally.
void rebuild_all_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                            const Box& box);

// True when either list may be stale (see above).
bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box);

}  // namespace mrf
