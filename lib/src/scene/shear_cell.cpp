#include "mrf/scene/shear_cell.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mrf/error.hpp"

namespace mrf {

WallParticles build_walls(const Box& box, double spacing) {
  WallParticles w;
  const int ny = static_cast<int>(std::ceil(box.ly / spacing - 1e-9));
  const int nz = static_cast<int>(std::ceil(box.lz / spacing - 1e-9));
  for (int side : {-1, 1})
    for (int iy = 0; iy < ny; ++iy)
      for (int iz = 0; iz < nz; ++iz) {
        w.x.emplace_back(side * 0.5 * box.gap, (iy + 0.5) * box.ly / ny, (iz + 0.5) * box.lz / nz);
        w.side.push_back(side);
      }
  return w;
}

std::size_t particle_count(const SceneConfig& c) {
  return static_cast<std::size_t>(
      std::llround(c.volume_fraction * c.gap * c.ly * c.lz / sphere_volume(c.radius)));
}

namespace {
// A hash grid of cells >= 2R for overlap checks during insertion.
struct InsertGrid {
  int nx, ny, nz;
  double x0, wx, wy, wz;
  std::vector<std::vector<std::uint32_t>> cells;
  int wrap(int i, int n) const { return (i % n + n) % n; }
  int cx(double x) const { return std::min(nx - 1, std::max(0, static_cast<int>((x - x0) / wx))); }
};
}  // namespace

FreeParticles place_particles(const SceneConfig& c, const std::string& where_phi) {
  const std::size_t n = particle_count(c);
  const double two_r = 2.0 * c.radius;
  const double x_max = 0.5 * c.gap - two_r;
  const Box box{c.gap, c.ly, c.lz};
  InsertGrid g;
  g.nx = std::max(1, static_cast<int>(2 * x_max / two_r));
  g.ny = std::max(1, static_cast<int>(c.ly / two_r));
  g.nz = std::max(1, static_cast<int>(c.lz / two_r));
  g.x0 = -x_max;
  g.wx = std::max(2 * x_max, 1e-300) / g.nx;
  g.wy = c.ly / g.ny;
  g.wz = c.lz / g.nz;
  g.cells.resize(static_cast<std::size_t>(g.nx) * g.ny * g.nz);
  FreeParticles p;
  Rng rng(c.seed);
  const std::size_t max_attempts = 2000 * n + 10000;
  std::size_t attempts = 0;
  while (p.x.size() < n) {
    if (++attempts > max_attempts)
      throw InputError("particles.volume_fraction", std::to_string(c.volume_fraction), where_phi,
                       "cannot be packed: random placement stopped at " + std::to_string(p.x.size()) +
                           " of " + std::to_string(n) + " spheres");
    const Vec3 q(-x_max + 2 * x_max * rng.uniform(), c.ly * rng.uniform(), c.lz * rng.uniform());
    const int ix = g.cx(q.x()), iy = static_cast<int>(q.y() / g.wy) % g.ny,
              iz = static_cast<int>(q.z() / g.wz) % g.nz;
    bool free_spot = true;
    for (int dx = -1; dx <= 1 && free_spot; ++dx) {
      if (ix + dx < 0 || ix + dx >= g.nx) continue;
      for (int dy = -1; dy <= 1 && free_spot; ++dy)
        for (int dz = -1; dz <= 1 && free_spot; ++dz) {
          const auto& cell = g.cells[((ix + dx) * g.ny + g.wrap(iy + dy, g.ny)) * g.nz + g.wrap(iz + dz, g.nz)];
          for (std::uint32_t j : cell)
            if (box.min_image(q - p.x[j]).squaredNorm() < two_r * two_r) {
              free_spot = false;
              break;
            }
        }
    }
    if (!free_spot) continue;
    g.cells[(ix * g.ny + iy) * g.nz + iz].push_back(static_cast<std::uint32_t>(p.x.size()));
    p.x.push_back(q);
  }
  // Numbered in slabs across the gap: in the order of the insertion cells
  // (x cell, then y cell, then z cell; each 2R or more wide). Shear along z
  // scrambles the z order over a strain unit, but x and y (gradient and
  // vorticity) change only by rearrangement, so spheres near in the cell
  // stay near in number: the threads' blocks of consecutive spheres
  // (contact solve, pair lists) are slabs that share few contacts, and a
  // sphere's neighbours sit close in memory.
  std::vector<Vec3> placed;
  placed.reserve(n);
  for (const auto& cell : g.cells)
    for (std::uint32_t j : cell) placed.push_back(p.x[j]);
  p.x = std::move(placed);
  p.v.assign(n, Vec3::Zero());
  p.f.assign(n, Vec3::Zero());
  return p;
}

ShearCell build_shear_cell(const SceneConfig& c, const std::string& where_phi) {
  ShearCell cell;
  cell.box = Box{c.gap, c.ly, c.lz};
  cell.walls = build_walls(cell.box, c.wall_spacing);
  cell.free = place_particles(c, where_phi);
  return cell;
}

}  // namespace mrf
