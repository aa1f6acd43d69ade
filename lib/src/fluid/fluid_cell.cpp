#include "mrf/fluid/fluid_cell.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/fluid/kernel.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/fluid/viscosity.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "mrf/neighbors/verlet_list.hpp"

namespace mrf {

namespace {

int count_along(double length, double dx) { return static_cast<int>(std::lround(length / dx)); }

// Call f(r_ab, r) for every periodic image of d = x_a - x_b closer than rc.
// A second image along y (z) can lie within rc only when ly (lz) < 2 rc;
// validation keeps ly, lz > rc, so no particle meets its own image.
template <class F>
void for_each_image(const Box& box, const MinImageYZ& mi, const Vec3& d, double rc, F&& f) {
  if (std::abs(d.x()) >= rc) return;  // x is not periodic: cheap rejection first
  const Vec3 m(d.x(), mi.wrap_y(d.y()), mi.wrap_z(d.z()));  // branch-free minimum image
  const double rc2 = rc * rc, dx2 = m.x() * m.x();
  const int ky = box.ly < 2.0 * rc ? 1 : 0;
  const int kz = box.lz < 2.0 * rc ? 1 : 0;
  for (int iz = -kz; iz <= kz; ++iz) {
    const double ez = m.z() + iz * box.lz;
    if (dx2 + ez * ez >= rc2) continue;
    for (int iy = -ky; iy <= ky; ++iy) {
      const double ey = m.y() + iy * box.ly;
      const double r2 = dx2 + ey * ey + ez * ez;
      if (r2 < rc2) f(Vec3(m.x(), ey, ez), std::sqrt(r2));
    }
  }
}

void add_wall(FluidCell& cell, int side, int layers) {
  const double dx = cell.params.spacing;
  const int ny = count_along(cell.box.ly, dx), nz = count_along(cell.box.lz, dx);
  const Vec3 v = wall_velocity(cell, side);
  FluidWallParticles& w = cell.wall;
  for (int l = 0; l < layers; ++l) {
    const double depth = (l + 0.5) * dx;
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        w.x.emplace_back(side * (0.5 * cell.box.gap + depth), (j + 0.5) * dx, (k + 0.5) * dx);
        w.v.push_back(v);
        w.depth.push_back(depth);
        w.side.push_back(side);
      }
  }
  w.rho.assign(w.x.size(), cell.params.density);
  w.p.assign(w.x.size(), 0.0);
}

}  // namespace

Vec3 wall_velocity(const FluidCell& cell, int side) {
  return mrf::wall_velocity(side, cell.params.shear_rate, cell.box.gap);
}

FluidCell build_fluid_cell(const Box& box, const FluidParams& params) {
  params.validate(box);
  FluidCell cell;
  cell.box = box;
  cell.params = params;
  cell.h = params.h();
  const double dx = params.spacing;
  // Mass rho0 dx^3 so the particles carry the true mass density; the
  // summation density is divided by the lattice sum S1 so that the
  // undisturbed lattice has density rho0 exactly (no spurious pressure).
  cell.mass = params.density * dx * dx * dx;
  cell.density_scale = 1.0 / lattice_kernel_sum(dx, cell.h);
  cell.c0 = sound_speed(params, box);
  cell.viscous_scale = morris_lattice_correction(dx, cell.h);
  const int nx = count_along(box.gap, dx), ny = count_along(box.ly, dx), nz = count_along(box.lz, dx);
  FluidParticles& f = cell.fluid;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        f.x.emplace_back(-0.5 * box.gap + (i + 0.5) * dx, (j + 0.5) * dx, (k + 0.5) * dx);
  f.v.assign(f.x.size(), Vec3::Zero());
  f.a_ext.assign(f.x.size(), Vec3::Zero());
  const int layers = static_cast<int>(std::ceil(k_kernel_support * cell.h / dx));
  add_wall(cell, -1, layers);
  add_wall(cell, +1, layers);
  refresh(cell);
  return cell;
}

SphPairs find_pairs(const FluidCell& cell) { return find_pairs(cell, k_kernel_support * cell.h); }

SphPairs find_pairs(const FluidCell& cell, double rc) {
  SphPairs out;
  out.fluid_fluid.reserve(cell.pairs.fluid_fluid.size());
  out.fluid_wall.reserve(cell.pairs.fluid_wall.size());
  const Box& box = cell.box;
  const double reach = 0.5 * box.gap + cell.wall.depth.back() + cell.params.spacing;
  CellGrid grid(box, -reach, reach, rc);
  const MinImageYZ mi(box);
  const auto& xf = cell.fluid.x;
  grid.bin(xf);
  for (std::uint32_t a = 0; a < xf.size(); ++a)
    grid.for_each_candidate(xf[a], [&](std::uint32_t b) {
      if (b <= a) return;
      for_each_image(box, mi, xf[a] - xf[b], rc,
                     [&](const Vec3& e, double r) { out.fluid_fluid.push_back({a, b, e, r}); });
    });
  const auto& xw = cell.wall.x;
  grid.bin(xw);
  for (std::uint32_t a = 0; a < xf.size(); ++a)
    grid.for_each_candidate(xf[a], [&](std::uint32_t b) {
      for_each_image(box, mi, xf[a] - xw[b], rc,
                     [&](const Vec3& e, double r) { out.fluid_wall.push_back({a, b, e, r}); });
    });
  return out;
}

namespace {
// Candidates within 2h + skin of the cell's positions, sorted by (a, b,
// image), so that the pairs, and the round-off of every sum over them, do
// not depend on when the candidates were built.
SphPairs sorted_candidates(const FluidCell& cell, double skin) {
  SphPairs c = find_pairs(cell, k_kernel_support * cell.h + skin);
  auto order = [](const SphPair& p, const SphPair& q) {
    if (p.a != q.a) return p.a < q.a;
    if (p.b != q.b) return p.b < q.b;
    if (p.r_ab.y() != q.r_ab.y()) return p.r_ab.y() < q.r_ab.y();
    return p.r_ab.z() < q.r_ab.z();
  };
  std::sort(c.fluid_fluid.begin(), c.fluid_fluid.end(), order);
  std::sort(c.fluid_wall.begin(), c.fluid_wall.end(), order);
  return c;
}

bool cache_stale(const FluidCell& cell, const SphPairCache& cache) {
  if (cache.x_fluid.size() != cell.fluid.size() || cache.x_wall.size() != cell.wall.size()) return true;
  const Box& box = cell.box;
  const double reach = k_kernel_support * cell.h + cache.skin;
  const double df = max_nonaffine_displacement(cell.fluid.x, cache.x_fluid, box, cache.strain);
  const double dw = max_nonaffine_displacement(cell.wall.x, cache.x_wall, box, cache.strain);
  // The separations are continued by minimum-image displacements: keep them
  // far below half the box.
  const double quarter = 0.25 * std::min(box.ly, box.lz);
  return skin_spent(2.0 * df, cache.strain, reach, cache.skin) ||
         skin_spent(df + dw, cache.strain, reach, cache.skin) ||
         max_displacement(cell.fluid.x, cache.x_fluid, box) > quarter ||
         max_displacement(cell.wall.x, cache.x_wall, box) > quarter;
}
}  // namespace

void restore_candidates(const FluidCell& cell, SphPairCache& cache) {
  if (cache.x_fluid.size() != cell.fluid.size() || cache.x_wall.size() != cell.wall.size()) {
    cache.candidates = {};
    cache.x_fluid.clear();  // rebuilt at the next update
    return;
  }
  FluidCell at_ref = cell;
  at_ref.fluid.x = cache.x_fluid;
  at_ref.wall.x = cache.x_wall;
  cache.candidates = sorted_candidates(at_ref, cache.skin);
}

void update_pairs(FluidCell& cell, SphPairCache& cache) {
  const double rc = k_kernel_support * cell.h;
  if (!(cache.skin > 0)) {
    cell.pairs = find_pairs(cell);
    return;
  }
  const Box& box = cell.box;
  if (cache_stale(cell, cache)) {
    cache.candidates = sorted_candidates(cell, cache.skin);
    cache.x_fluid = cell.fluid.x;
    cache.x_wall = cell.wall.x;
    cache.strain = 0;
    ++cache.builds;
  }
  // The separation is computed as find_pairs does (minimum image, then the
  // image of the candidate: the one nearest to its reference separation
  // moved by the displacements), so the pairs equal a fresh search bit for bit.
  const MinImageYZ mi(box);
  auto moved = [&](const Vec3& x, const Vec3& ref) {
    return Vec3(x.x() - ref.x(), mi.wrap_y(x.y() - ref.y()), mi.wrap_z(x.z() - ref.z()));
  };
  const double rc2 = rc * rc;
  auto add = [&](const SphPair& c, const Vec3& xa, const Vec3& xb, const Vec3& predicted, std::vector<SphPair>& out) {
    const Vec3 d = xa - xb;
    const Vec3 m(d.x(), mi.wrap_y(d.y()), mi.wrap_z(d.z()));
    const double iy = std::nearbyint((predicted.y() - m.y()) / box.ly), iz = std::nearbyint((predicted.z() - m.z()) / box.lz);
    const double ey = m.y() + static_cast<int>(iy) * box.ly, ez = m.z() + static_cast<int>(iz) * box.lz;
    const double r2 = m.x() * m.x() + ey * ey + ez * ez;
    if (r2 < rc2) out.push_back({c.a, c.b, Vec3(m.x(), ey, ez), std::sqrt(r2)});
  };
  SphPairs& out = cell.pairs;
  out.fluid_fluid.clear();
  out.fluid_wall.clear();
  for (const SphPair& c : cache.candidates.fluid_fluid)
    add(c, cell.fluid.x[c.a], cell.fluid.x[c.b],
        c.r_ab + moved(cell.fluid.x[c.a], cache.x_fluid[c.a]) - moved(cell.fluid.x[c.b], cache.x_fluid[c.b]),
        out.fluid_fluid);
  for (const SphPair& c : cache.candidates.fluid_wall)
    add(c, cell.fluid.x[c.a], cell.wall.x[c.b],
        c.r_ab + moved(cell.fluid.x[c.a], cache.x_fluid[c.a]) - moved(cell.wall.x[c.b], cache.x_wall[c.b]),
        out.fluid_wall);
}

}  // namespace mrf
