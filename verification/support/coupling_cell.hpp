// The fluid cell and random particles of the coupling tests
// (verification/coupling/test_exchange.cpp, test_coupling_pairs.cpp):
// simple cubic SPH lattice, h/dx = 1.3, Wendland C2, MRF-scale particles.
#pragma once
#include <cstddef>
#include <random>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf::test {

inline constexpr double kDx = 5e-6;       // fluid spacing (m)
inline constexpr double kR = 2.5e-6;      // DEM radius (m), d = 5 um
inline const double kVp = sphere_volume(kR);

// Fluid at rest, h = 1.3 dx; by default gap 24 dx, ly = lz = 12 dx (>= 4h).
inline FluidCell make_cell(const Box& box = Box{24 * kDx, 12 * kDx, 12 * kDx}) {
  FluidParams p;
  p.viscosity = 0.1;
  p.density = 1000.0;
  p.spacing = kDx;
  p.sound_speed = 1.0;
  return build_fluid_cell(box, p);
}

inline std::vector<Vec3> random_points(std::size_t n, double x_lo, double x_hi, const Box& box, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> ux(x_lo, x_hi), uy(0.0, box.ly), uz(0.0, box.lz);
  std::vector<Vec3> out;
  for (std::size_t k = 0; k < n; ++k) out.emplace_back(ux(gen), uy(gen), uz(gen));
  return out;
}

// Spheres at rest on a simple cubic lattice of spacing a, nx layers from
// the lower wall plane x = -gap/2 and ny x nz across (the fixed beds of
// test_coupled_suspension.cpp and test_coupled_carrier.cpp).
inline ShearCell sphere_lattice(const Box& box, double a, int nx, int ny, int nz) {
  ShearCell cell;
  cell.box = box;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) cell.free.x.emplace_back(-0.5 * box.gap + (i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a);
  cell.free.v.assign(cell.free.size(), Vec3::Zero());
  cell.free.f.assign(cell.free.size(), Vec3::Zero());
  return cell;
}

}  // namespace mrf::test
