// Shear-cell box: bounded in x by the walls, periodic in y and z.
// Wall-particle centres sit at x = -gap/2 and x = +gap/2; y in [0, ly), z in [0, lz).
#pragma once
#include <cmath>

#include "mrf/vec.hpp"

namespace mrf {

struct Box {
  double gap = 0;  // wall-centre to wall-centre distance along x (m)
  double ly = 0;   // periodic length along y, vorticity (m)
  double lz = 0;   // periodic length along z, flow (m)

  double volume() const { return gap * ly * lz; }
  double wall_area() const { return ly * lz; }

  // Minimum-image separation (x is not periodic).
  Vec3 min_image(Vec3 d) const {
    d.y() -= ly * std::nearbyint(d.y() / ly);
    d.z() -= lz * std::nearbyint(d.z() / lz);
    return d;
  }
  // Map a position back into the primary cell in y and z.
  void wrap(Vec3& p) const {
    p.y() -= ly * std::floor(p.y() / ly);
    p.z() -= lz * std::floor(p.z() / lz);
  }
};

}  // namespace mrf
