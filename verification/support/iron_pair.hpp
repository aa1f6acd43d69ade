// The scene of two iron spheres (R = 2.5 um, M = 1e6 A/m, 200 GPa, in an
// oil of 0.1 Pa s) for tests that build cells by hand.
#pragma once
#include "mrf/scene/config.hpp"

namespace mrf::test {

inline SceneConfig iron_pair_config(double radius, double magnetization, double dipole_cutoff) {
  SceneConfig c;
  c.radius = radius;
  c.density = 7800;
  c.magnetization = magnetization;
  c.youngs_modulus = 200e9;
  c.poisson_ratio = 0.3;
  c.viscosity = 0.1;
  c.dipole_cutoff = dipole_cutoff;
  return c;
}

}  // namespace mrf::test
