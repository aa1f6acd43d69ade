// The shear cell: walls of overlapping non-magnetic spheres at x = -+gap/2
// and magnetic spheres placed at random without overlap between them.
#pragma once
#include <cstdint>

#include "mrf/box.hpp"
#include "mrf/scene/config.hpp"
#include "mrf/state.hpp"

namespace mrf {

struct ShearCell {
  Box box;
  FreeParticles free;
  WallParticles walls;
};

// One square layer of wall spheres on each wall plane; the lattice spacing is
// the largest value <= `spacing` that fits the periodic lengths.
WallParticles build_walls(const Box& box, double spacing);

// Number of magnetic spheres for volume fraction phi = n V_p / (gap ly lz).
std::size_t particle_count(const SceneConfig& c);

// Random sequential addition, seeded and reproducible on every platform:
// centres uniform in y, z and in |x| <= gap/2 - 2R (clear of the wall
// spheres), no two closer than 2R, numbered in slabs across the gap (by
// cells of 2R or more: x cell, then y cell, then z cell, an order that shear
// along z keeps). Throws InputError on
// particles.volume_fraction when the fraction cannot be packed.
FreeParticles place_particles(const SceneConfig& c, const std::string& where_phi = {});

ShearCell build_shear_cell(const SceneConfig& c, const std::string& where_phi = {});

// Deterministic uniform double in [0,1) from a 64-bit generator state
// (splitmix64), so placements do not depend on the standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

 private:
  std::uint64_t s_;
};

}  // namespace mrf
