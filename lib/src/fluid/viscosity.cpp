#include "mrf/fluid/viscosity.hpp"

#include <cmath>

namespace mrf {

double wall_viscous_weight(const FluidCell& c, const SphPair& pr) {
  const int side = c.wall.side[pr.b];
  const double beta = morris_wall_factor(c.wall.depth[pr.b], wall_distance(c, c.fluid.x[pr.a], side),
                                         0.5 * c.params.spacing);
  return beta * morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), c.fluid.rho[pr.a], c.wall.rho[pr.b]);
}

double morris_lattice_correction(double dx, double h) {
  const int n = static_cast<int>(std::ceil(k_kernel_support * h / dx));
  double s2 = 0.0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        const double r = dx * std::sqrt(double(i * i + j * j + k * k));
        const double x = dx * i;
        s2 -= kernel_dwdr_over_r(r, h) * x * x * r * r / (r * r + k_morris_eps * h * h);
      }
  return 1.0 / (dx * dx * dx * s2);
}

Vec3 wall_viscous_acceleration(const FluidCell& c, const SphPair& pr) {
  return wall_viscous_weight(c, pr) * (c.fluid.v[pr.a] - c.wall.v[pr.b]);
}

void add_viscous_acceleration(const FluidCell& c, std::vector<Vec3>& a) {
  const auto& v = c.fluid.v;
  const auto& rho = c.fluid.rho;
  for (const SphPair& pr : c.pairs.fluid_fluid) {
    const double k = morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), rho[pr.a], rho[pr.b]);
    const Vec3 dv = k * (v[pr.a] - v[pr.b]);
    a[pr.a] += dv;
    a[pr.b] -= dv;
  }
  for (const SphPair& pr : c.pairs.fluid_wall) a[pr.a] += wall_viscous_acceleration(c, pr);
}

}  // namespace mrf
