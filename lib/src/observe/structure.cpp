#include "mrf/observe/structure.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include "mrf/neighbors/cell_list.hpp"
#include "parallel_blocks.hpp"

namespace mrf {
namespace {

constexpr std::size_t k_spheres_per_thread = 1000;  // the least a thread takes

std::uint32_t root(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];  // path halving
  return i;
}

}  // namespace

ClusterStats cluster_stats(const ShearCell& cell, double radius, double touch) {
  ClusterStats out;
  const auto& x = cell.free.x;
  const std::size_t n = x.size();
  if (n == 0) return out;
  const double reach = (2.0 + touch) * radius, reach2 = reach * reach;
  const double half = 0.5 * cell.box.gap;
  CellGrid grid(cell.box, -half - radius, half + radius, reach);
  grid.bin(x);
  const MinImageYZ mi(cell.box);
  std::vector<std::uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  // The touching pairs found by blocks of spheres on threads (in_blocks),
  // joined serially: the clusters do not depend on the order of the joins.
  // Equal blocks: the scan of the neighbour cells, the same for every
  // sphere, is most of the work (cut for the pairs j > i, the second
  // thread took 70 %).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> touching_pairs;
  detail::in_blocks(
      n, k_spheres_per_thread, touching_pairs,
      [&](std::size_t lo, std::size_t hi, std::vector<std::pair<std::uint32_t, std::uint32_t>>& mine) {
        for (auto i = static_cast<std::uint32_t>(lo); i < hi; ++i)
          grid.for_each_candidate(x[i], [&](std::uint32_t j) {
            if (j > i && mi.norm2(x[i], x[j]) < reach2) mine.emplace_back(i, j);
          });
      });
  for (const auto& [i, j] : touching_pairs) {
    const std::uint32_t a = root(parent, i), b = root(parent, j);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  // which walls each cluster touches: bit 1 the lower (side -1), bit 2 the upper
  std::vector<std::uint8_t> walls(n, 0);
  for (std::size_t w = 0; w < cell.walls.size(); ++w)
    grid.for_each_candidate(cell.walls.x[w], [&](std::uint32_t j) {
      if (mi.norm2(cell.walls.x[w], x[j]) >= reach2) return;
      std::uint8_t& touched = walls[root(parent, j)];
      touched = static_cast<std::uint8_t>(touched | (cell.walls.side[w] < 0 ? 1u : 2u));
    });
  std::vector<std::uint32_t> size(n, 0);
  for (std::uint32_t i = 0; i < n; ++i) ++size[root(parent, i)];
  std::size_t spanning = 0, touching = 0, largest = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = root(parent, i);
    spanning += walls[r] == 3 ? 1 : 0;
    touching += walls[r] != 0 ? 1 : 0;
    if (r == i) {
      ++out.clusters;
      largest = std::max<std::size_t>(largest, size[i]);
    }
  }
  const double inv = 1.0 / static_cast<double>(n);
  out.spanning_fraction = static_cast<double>(spanning) * inv;
  out.wall_fraction = static_cast<double>(touching) * inv;
  out.largest_fraction = static_cast<double>(largest) * inv;
  return out;
}

}  // namespace mrf
