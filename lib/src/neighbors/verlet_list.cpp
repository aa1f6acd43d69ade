#include "mrf/neighbors/verlet_list.hpp"

#include <algorithm>
#include <cmath>

namespace mrf {

double max_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box) {
  const MinImageYZ mi(box);
  double max2 = 0;
  for (std::size_t i = 0; i < x.size(); ++i) max2 = std::max(max2, mi.norm2(x[i], ref[i]));
  return std::sqrt(max2);
}

namespace {

bool ff_stale(const DemPairLists& l, const FreeParticles& free, const Box& box) {
  if (l.builds == 0 || l.x_ref.size() != free.size() || l.ff.rows() != free.size()) return true;
  return 2.0 * max_displacement(free.x, l.x_ref, box) > l.skin;
}

bool fw_stale(const DemPairLists& l, const FreeParticles& free, const WallParticles& walls, const Box& box) {
  if (l.fw_range <= 0) return false;
  if (l.builds == 0 || l.x_ref_fw.size() != free.size() || l.walls_ref != walls.size()) return true;
  return max_displacement(free.x, l.x_ref_fw, box) + l.wall_travel > l.skin;
}

void build_ff(DemPairLists& lists, const FreeParticles& free, const Box& box) {
  self_pair_rows(free.x, box, lists.ff_range + lists.skin, lists.ff);
  lists.x_ref = free.x;
}

void build_fw(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls, const Box& box) {
  lists.fw.clear();
  if (lists.fw_range > 0) lists.fw = cross_pairs(free.x, walls.x, box, lists.fw_range + lists.skin);
  lists.x_ref_fw = free.x;
  lists.walls_ref = walls.size();
  lists.wall_travel = 0;
}
}  // namespace

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin) {
  DemPairLists l;
  l.ff_range = ff_range;
  l.fw_range = fw_range;
  l.skin = skin;
  return l;
}

void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box) {
  const bool ff = ff_stale(lists, free, box);
  const bool fw = fw_stale(lists, free, walls, box) || (lists.fw_range <= 0 && !lists.fw.empty());
  if (ff) build_ff(lists, free, box);
  if (fw) build_fw(lists, free, walls, box);
  if (ff || fw) ++lists.builds;
}

void rebuild_all_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                            const Box& box) {
  build_ff(lists, free, box);
  build_fw(lists, free, walls, box);
  ++lists.builds;
}

bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box) {
  if (lists.builds == 0 || lists.x_ref.size() != free.size() || lists.ff.rows() != free.size()) return true;
  if (2.0 * max_displacement(free.x, lists.x_ref, box) > lists.skin) return true;
  if (lists.fw_range <= 0) return false;
  if (lists.x_ref_fw.size() != free.size()) return true;
  return max_displacement(free.x, lists.x_ref_fw, box) + lists.wall_travel > lists.skin;
}

}  // namespace mrf
