// Particle state as structures of arrays, no behaviour.
#pragma once
#include <cstddef>
#include <vector>

#include "mrf/vec.hpp"

namespace mrf {

// Free (magnetic) particles: all of one species (radius, mass, dipole moment
// along +x are scene constants, kept in the model's parameters).
struct FreeParticles {
  std::vector<Vec3> x;  // position (m), y and z wrapped into the box
  std::vector<Vec3> v;  // velocity (m/s)
  std::vector<Vec3> f;  // non-drag force of the current step (N)
  std::size_t size() const { return x.size(); }
};

// Wall particles: non-magnetic spheres moving with prescribed velocity
// (0, 0, gdot * x_wall). side = -1 lower wall (x = -gap/2), +1 upper wall.
struct WallParticles {
  std::vector<Vec3> x;
  std::vector<int> side;
  std::size_t size() const { return x.size(); }
};

}  // namespace mrf
