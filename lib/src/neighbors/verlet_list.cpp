#include "mrf/neighbors/verlet_list.hpp"

#include <algorithm>
#include <cmath>

namespace mrf {

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin) {
  DemPairLists l;
  l.ff_range = ff_range;
  l.fw_range = fw_range;
  l.skin = skin;
  return l;
}

void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box) {
  lists.ff = self_pairs(free.x, box, lists.ff_range + lists.skin);
  lists.fw.clear();
  if (lists.fw_range > 0) lists.fw = cross_pairs(free.x, walls.x, box, lists.fw_range + lists.skin);
  lists.x_ref = free.x;
  lists.wall_travel = 0;
  ++lists.builds;
}

bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box) {
  if (lists.builds == 0 || lists.x_ref.size() != free.size()) return true;
  double max2 = 0;
  for (std::size_t i = 0; i < free.size(); ++i)
    max2 = std::max(max2, box.min_image(free.x[i] - lists.x_ref[i]).squaredNorm());
  const double d = std::sqrt(max2);
  return d + std::max(d, lists.wall_travel) > lists.skin;
}

}  // namespace mrf
