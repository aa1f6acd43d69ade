// Cell-list neighbour search in the shear-cell box (periodic in y and z,
// bounded in x). Built from positions and a box only; knows no physics.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "mrf/box.hpp"

namespace mrf {

using IndexPair = std::pair<std::uint32_t, std::uint32_t>;

// A list offset or index as the 32-bit value the lists store; a count past
// 2^32 - 1 (about 4e7 spheres at 100 list entries each, docs/scaling.md) is
// a std::length_error naming `what`, never a silent wrap.
std::uint32_t checked_index(std::size_t n, const char* what);

// A half pair list stored by rows (CSR): the partners of point i are
// k[start[i]], ..., k[start[i + 1] - 1], all with index > i.
struct PairRows {
  std::vector<std::uint32_t> start;  // size points + 1 (empty when there are no points)
  std::vector<std::uint32_t> k;
  std::size_t size() const { return k.size(); }
  std::size_t rows() const { return start.empty() ? 0 : start.size() - 1; }
};

// Branch-free minimum image in y and z with precomputed inverse lengths.
// Rounds to nearest (ties to even, as std::nearbyint) by adding and
// subtracting 1.5 * 2^52, exact for |d / l| < 2^51; needs IEEE evaluation
// (no -ffast-math), which the build uses.
struct MinImageYZ {
  double ly, lz, inv_ly, inv_lz;
  explicit MinImageYZ(const Box& b) : ly(b.ly), lz(b.lz), inv_ly(1.0 / b.ly), inv_lz(1.0 / b.lz) {}
  static double round_nearest(double t) {
    constexpr double k_magic = 6755399441055744.0;  // 1.5 * 2^52
    return (t + k_magic) - k_magic;
  }
  double wrap_y(double dy) const { return dy - ly * round_nearest(dy * inv_ly); }
  double wrap_z(double dz) const { return dz - lz * round_nearest(dz * inv_lz); }
  // minimum image of a - b
  Vec3 delta(const Vec3& a, const Vec3& b) const {
    return Vec3(a.x() - b.x(), wrap_y(a.y() - b.y()), wrap_z(a.z() - b.z()));
  }
  // |minimum image of a - b|^2
  double norm2(const Vec3& a, const Vec3& b) const {
    const double dx = a.x() - b.x(), dy = wrap_y(a.y() - b.y()), dz = wrap_z(a.z() - b.z());
    return dx * dx + dy * dy + dz * dz;
  }
};

// A uniform grid of cells no smaller than `min_cell` along each axis.
// Along y or z a periodic direction with fewer than 3 cells is collapsed to
// one cell (every point is then a candidate along it), which keeps the
// search correct for any box.
class CellGrid {
 public:
  CellGrid(const Box& box, double x_lo, double x_hi, double min_cell);

  // Sort points into cells (counting sort; no allocation after the first call
  // with the same number of points).
  void bin(const std::vector<Vec3>& pts);

  // Call f(j) for every binned point j in the 27 cells around position p
  // (each point at most once).
  template <class F>
  void for_each_candidate(const Vec3& p, F&& f) const {
    const int cx = cell_x(p.x()), cy = cell_y(p.y()), cz = cell_z(p.z());
    const int dx_lo = cx > 0 ? -1 : 0, dx_hi = cx < nx_ - 1 ? 1 : 0;
    const int dy_lo = ny_ >= 3 ? -1 : 0, dy_hi = ny_ >= 3 ? 1 : 0;
    const int dz_lo = nz_ >= 3 ? -1 : 0, dz_hi = nz_ >= 3 ? 1 : 0;
    for (int dx = dx_lo; dx <= dx_hi; ++dx)
      for (int dy = dy_lo; dy <= dy_hi; ++dy)
        for (int dz = dz_lo; dz <= dz_hi; ++dz) {
          const int c = index(cx + dx, (cy + dy + ny_) % ny_, (cz + dz + nz_) % nz_);
          for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) f(order_[k]);
        }
  }

  int cells() const { return nx_ * ny_ * nz_; }

 private:
  int cell_x(double x) const;
  int cell_y(double y) const;
  int cell_z(double z) const;
  int index(int ix, int iy, int iz) const { return (ix * ny_ + iy) * nz_ + iz; }

  Box box_;
  double x_lo_, inv_wx_, inv_wy_, inv_wz_;
  int nx_, ny_, nz_;
  std::vector<std::uint32_t> start_, order_, cell_of_, fill_;
};

// All pairs i < j of `pts` closer than `cutoff` (minimum image), via cells.
std::vector<IndexPair> self_pairs(const std::vector<Vec3>& pts, const Box& box, double cutoff);
// The same pairs as rows i -> {j > i}, written into `out` (reuses its storage).
void self_pair_rows(const std::vector<Vec3>& pts, const Box& box, double cutoff, PairRows& out);
// All pairs (i in a, j in b) closer than `cutoff`, via cells.
std::vector<IndexPair> cross_pairs(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                                   const Box& box, double cutoff);

// O(N^2) oracles for tests.
std::vector<IndexPair> brute_force_self_pairs(const std::vector<Vec3>& pts, const Box& box,
                                              double cutoff);
std::vector<IndexPair> brute_force_cross_pairs(const std::vector<Vec3>& a,
                                               const std::vector<Vec3>& b, const Box& box,
                                               double cutoff);

}  // namespace mrf
