#include "mrf/neighbors/cell_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "parallel_blocks.hpp"

namespace mrf {

namespace {
// spheres per thread below which a list build stays serial
constexpr std::size_t k_rows_per_thread = 1000;
int cells_along(double length, double min_cell) {
  return std::max(1, static_cast<int>(std::floor(length / min_cell)));
}
void extent(const std::vector<Vec3>& a, double& lo, double& hi) {
  for (const Vec3& p : a) {
    lo = std::min(lo, p.x());
    hi = std::max(hi, p.x());
  }
}
}  // namespace

CellGrid::CellGrid(const Box& box, double x_lo, double x_hi, double min_cell)
    : box_(box), x_lo_(x_lo) {
  nx_ = cells_along(x_hi - x_lo, min_cell);
  ny_ = cells_along(box.ly, min_cell);
  nz_ = cells_along(box.lz, min_cell);
  if (ny_ < 3) ny_ = 1;
  if (nz_ < 3) nz_ = 1;
  inv_wx_ = nx_ / std::max(x_hi - x_lo, std::numeric_limits<double>::min());
  inv_wy_ = ny_ / box.ly;
  inv_wz_ = nz_ / box.lz;
}

int CellGrid::cell_x(double x) const {
  return std::clamp(static_cast<int>((x - x_lo_) * inv_wx_), 0, nx_ - 1);
}
int CellGrid::cell_y(double y) const {
  const double w = y - box_.ly * std::floor(y / box_.ly);
  return std::clamp(static_cast<int>(w * inv_wy_), 0, ny_ - 1);
}
int CellGrid::cell_z(double z) const {
  const double w = z - box_.lz * std::floor(z / box_.lz);
  return std::clamp(static_cast<int>(w * inv_wz_), 0, nz_ - 1);
}

void CellGrid::bin(const std::vector<Vec3>& pts) {
  const int nc = cells();
  start_.assign(nc + 1, 0);
  cell_of_.resize(pts.size());
  order_.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const int c = index(cell_x(pts[i].x()), cell_y(pts[i].y()), cell_z(pts[i].z()));
    cell_of_[i] = static_cast<std::uint32_t>(c);
    ++start_[c + 1];
  }
  for (int c = 0; c < nc; ++c) start_[c + 1] += start_[c];
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < pts.size(); ++i)
    order_[fill_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
}

std::vector<IndexPair> self_pairs(const std::vector<Vec3>& pts, const Box& box, double cutoff) {
  std::vector<IndexPair> out;
  if (pts.empty()) return out;
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  extent(pts, lo, hi);
  CellGrid grid(box, lo, hi, cutoff);
  grid.bin(pts);
  const double rc2 = cutoff * cutoff;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    grid.for_each_candidate(pts[i], [&](std::uint32_t j) {
      if (j <= i) return;
      if (box.min_image(pts[i] - pts[j]).squaredNorm() < rc2)
        out.emplace_back(static_cast<std::uint32_t>(i), j);
    });
  }
  return out;
}

std::uint32_t checked_index(std::size_t n, const char* what) {
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error(std::string(what) + ": " + std::to_string(n) +
                            " entries exceed the 32-bit indices of the lists (at most 4294967295): the cell is too "
                            "large for one process (docs/scaling.md)");
  return static_cast<std::uint32_t>(n);
}

void self_pair_rows(const std::vector<Vec3>& pts, const Box& box, double cutoff, PairRows& out) {
  // the last list's row starts, if it was a list of these spheres (below)
  std::vector<std::uint32_t> last;
  if (out.start.size() == pts.size() + 1) last.swap(out.start);
  out.k.clear();
  out.start.assign(pts.empty() ? 0 : pts.size() + 1, 0);
  if (pts.empty()) return;
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  extent(pts, lo, hi);
  CellGrid grid(box, lo, hi, cutoff);
  grid.bin(pts);
  const double rc2 = cutoff * cutoff;
  const MinImageYZ mi(box);
  // Rows in blocks on threads (detail::in_blocks): each block's partners in
  // its own list, row ends counted within the block and shifted to the
  // joined list after, so the rows are the serial ones whatever the threads.
  // Row i holds the partners j > i, so how the pairs fall into rows depends
  // on the spheres' order (in a random order, row i's share falls as i
  // grows: equal blocks of rows left the first thread 70 % of the work on
  // the paper cell). The blocks are cut for equal shares of the last list's
  // pairs, which a rebuild changes little; equal blocks for a first list.
  const std::size_t n = pts.size();
  const auto bound = [&last](std::size_t rows, std::size_t blk, std::size_t blocks) {
    return last.empty() ? detail::block_bound(rows, blk, blocks) : detail::share_bound(last, blk, blocks);
  };
  const std::vector<std::size_t> begin = detail::in_blocks(
      n, k_rows_per_thread, out.k,
      [&](std::size_t r0, std::size_t r1, std::vector<std::uint32_t>& mine) {
        for (std::size_t i = r0; i < r1; ++i) {
          const Vec3 xi = pts[i];
          grid.for_each_candidate(xi, [&](std::uint32_t j) {
            if (j <= i) return;
            if (mi.norm2(xi, pts[j]) < rc2) mine.push_back(j);
          });
          out.start[i + 1] = checked_index(mine.size(), "pair list");
        }
      },
      bound);
  const std::size_t blocks = begin.size();
  for (std::size_t b = 1; b < blocks; ++b)
    for (std::size_t i = bound(n, b, blocks); i < bound(n, b + 1, blocks); ++i)
      out.start[i + 1] = checked_index(out.start[i + 1] + begin[b], "pair list");
}

std::vector<IndexPair> cross_pairs(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                                   const Box& box, double cutoff) {
  std::vector<IndexPair> out;
  if (a.empty() || b.empty()) return out;
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  extent(a, lo, hi);
  extent(b, lo, hi);
  CellGrid grid(box, lo, hi, cutoff);
  grid.bin(b);
  const double rc2 = cutoff * cutoff;
  const MinImageYZ mi(box);
  // by blocks of a's points on threads, joined in order: the serial list
  constexpr std::size_t k_points_per_thread = 1024;
  detail::in_blocks(a.size(), k_points_per_thread, out, [&](std::size_t i0, std::size_t i1, std::vector<IndexPair>& mine) {
    for (std::size_t i = i0; i < i1; ++i)
      grid.for_each_candidate(a[i], [&](std::uint32_t j) {
        if (mi.norm2(a[i], b[j]) < rc2) mine.emplace_back(static_cast<std::uint32_t>(i), j);
      });
  });
  return out;
}

std::vector<IndexPair> brute_force_self_pairs(const std::vector<Vec3>& pts, const Box& box,
                                              double cutoff) {
  std::vector<IndexPair> out;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j)
      if (box.min_image(pts[i] - pts[j]).squaredNorm() < cutoff * cutoff)
        out.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
  return out;
}

std::vector<IndexPair> brute_force_cross_pairs(const std::vector<Vec3>& a,
                                               const std::vector<Vec3>& b, const Box& box,
                                               double cutoff) {
  std::vector<IndexPair> out;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j)
      if (box.min_image(a[i] - b[j]).squaredNorm() < cutoff * cutoff)
        out.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
  return out;
}

}  // namespace mrf
