// State of the SPH carrier fluid in the shear cell: fluid particles, wall
// particles and the neighbour pairs, as plain structures of arrays.
//
// Geometry (DESIGN.md): the no-slip planes are x = -gap/2 and x = +gap/2, the
// DEM wall-sphere centres. Fluid particles start on a simple cubic lattice
// at x = -gap/2 + (i + 1/2) dx; wall particles continue that lattice in
// ceil(2h/dx) layers beyond each plane, so a fluid particle next to the wall
// has full kernel support, and move rigidly with v = (0, 0, gdot x_wall).
// y and z are periodic.
//
// Invariant kept by build_fluid_cell and the steps: `pairs`, `rho`, `p` and
// the wall pressures are those of the current positions (refresh()).
#pragma once
#include <cstdint>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/fluid/fluid_params.hpp"

namespace mrf {

struct FluidParticles {
  std::vector<Vec3> x;      // position (m), y and z wrapped into the box
  std::vector<Vec3> v;      // velocity (m/s)
  std::vector<Vec3> a_ext;  // extra acceleration (m/s^2): hook for the DEM back-reaction (REFERENCE §6)
  std::vector<double> rho;  // summation density (kg/m^3); superficial eps rho_f when eps is set
  std::vector<double> p;    // pressure (Pa)
  // Porosity eps in (0, 1] for the averaged equations of the coupled models
  // (REFERENCE §6): the EOS takes the intrinsic density rho/eps. Empty for a
  // pure fluid (eps = 1), so fluid-only runs are unchanged.
  std::vector<double> eps;
  // EOS reference of each particle's intrinsic density (kg/m^3), carried
  // with the particle; empty = params.density. The coupled models set it to
  // params.density, or with fluid.eos_reference = "start" to the intrinsic
  // density of the start, which is then free of pressure.
  std::vector<double> rest_density;
  std::size_t size() const { return x.size(); }
};

struct FluidWallParticles {
  std::vector<Vec3> x;      // position (m)
  std::vector<Vec3> v;      // prescribed wall velocity (m/s)
  std::vector<double> depth;  // distance beyond the wall plane (m), > 0
  std::vector<int> side;    // -1 lower wall, +1 upper wall
  std::vector<double> rho;  // density from the inverse EOS of p (kg/m^3)
  std::vector<double> p;    // extrapolated pressure, Adami et al. 2012 (Pa)
  std::size_t size() const { return x.size(); }
};

// One interacting pair within the kernel support, with the separation of
// the periodic image that interacts: r_ab = x_a - x_b (m), r = |r_ab|.
// When ly or lz < 4h a pair can interact through two images; each image is
// then its own entry.
struct SphPair {
  std::uint32_t a, b;
  Vec3 r_ab;
  double r;
};

struct SphPairs {
  std::vector<SphPair> fluid_fluid;  // a < b, both fluid, each image once
  std::vector<SphPair> fluid_wall;   // a fluid, b wall
};

struct FluidCell {
  Box box;
  FluidParams params;
  double h = 0;            // smoothing length (m)
  double mass = 0;         // particle mass rho0 dx^3, fluid and wall (kg)
  double density_scale = 1;  // 1/S1 = 1/lattice_kernel_sum: summation density normalisation (1)
  double c0 = 0;           // sound speed (m/s)
  double viscous_scale = 1;  // morris_lattice_correction (1)
  FluidParticles fluid;
  FluidWallParticles wall;
  SphPairs pairs;
  double time = 0;         // s
  std::int64_t steps = 0;
};

// Lattice of fluid at rest between the walls (params validated here).
FluidCell build_fluid_cell(const Box& box, const FluidParams& params);

// Velocity of the wall on `side` (-1 lower, +1 upper): (0, 0, gdot side gap/2).
Vec3 wall_velocity(const FluidCell& cell, int side);

// Recompute the neighbour pairs, summation densities, fluid pressures and
// wall pressures at the current positions (pressure from the intrinsic
// density rho/eps when fluid.eps is set).
void refresh(FluidCell& cell);
// The same with the pairs from a Verlet cache (update_pairs, below).
struct SphPairCache;
void refresh(FluidCell& cell, SphPairCache& cache);

// Pressures and wall densities from the current densities and porosities,
// without a new pair search (refresh() ends with it). With porosity the wall
// particles take the Shepard mean eps_w of their fluid neighbours and the
// superficial density eps_w x eos_density(p_w), like the fluid they mirror,
// and a wall pressure clipped at 0 (no adhesion, see wcsph.cpp).
void update_pressures(FluidCell& cell);

// Neighbour pairs of the current positions (cell lists, periodic images).
// `reach` (m): pairs closer than that; default the kernel support 2h.
SphPairs find_pairs(const FluidCell& cell);
SphPairs find_pairs(const FluidCell& cell, double reach);

// Verlet candidates of the SPH pairs: the pairs within 2h + skin at the
// reference positions, each with its separation there. While the bound of
// neighbors/verlet_list.hpp holds (non-affine displacements plus the
// imposed strain since the build times the reach; the SPH wall particles
// move with their wall plane, so their non-affine part is the strain times
// their depth), every pair within 2h is a candidate, and its separation now
// is r_ab(ref) + d_a - d_b with the displacements d since the reference
// (minimum image: positions are wrapped in y and z each step, and the cache
// is rebuilt before any displacement reaches a quarter of the box). The
// pairs come sorted by (a, b, image), whenever the cache was built.
struct SphPairCache {
  double skin = 0;              // m; 0 = search every time
  SphPairs candidates;
  std::vector<Vec3> x_fluid, x_wall;  // reference positions
  double strain = 0;            // imposed strain since the build (signed); the caller adds gdot dt
  long builds = 0;
  // Checkpoints: the reference positions and the strain; the candidates are
  // found again from the reference positions (restore_candidates).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.x_fluid, s.x_wall, s.strain, s.builds);
  }
};

// cell.pairs for the current positions, from the cache (rebuilt when due).
void update_pairs(FluidCell& cell, SphPairCache& cache);
// The candidates of a loaded cache, from its reference positions: the list
// the cache held when it was saved.
void restore_candidates(const FluidCell& cell, SphPairCache& cache);

}  // namespace mrf
