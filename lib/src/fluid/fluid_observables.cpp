#include "mrf/fluid/fluid_observables.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/fluid/wcsph.hpp"

namespace mrf {

std::array<Vec3, 2> wall_force_on_fluid(const FluidCell& c) {
  std::array<Vec3, 2> force{Vec3::Zero(), Vec3::Zero()};
  const auto& f = c.fluid;
  for (const SphPair& pr : c.pairs.fluid_wall) {
    const Vec3 a = pressure_pair_acceleration(c.mass, f.p[pr.a], f.rho[pr.a], c.wall.p[pr.b],
                                              c.wall.rho[pr.b], pr.r_ab, pr.r, c.h) +
                   wall_viscous_acceleration(c, pr);
    force[c.wall.side[pr.b] < 0 ? 0 : 1] += c.mass * a;
  }
  return force;
}

FluidWallStress wall_shear_stress(const FluidCell& c) {
  const auto force = wall_force_on_fluid(c);
  const double area = c.box.wall_area();
  FluidWallStress s{};
  s.lower = -force[0].z() / area;
  s.upper = force[1].z() / area;
  s.tau = 0.5 * (s.lower + s.upper);
  return s;
}

std::vector<ProfileBin> velocity_profile(const FluidCell& c, int nbins) {
  std::vector<ProfileBin> bins(static_cast<std::size_t>(std::max(nbins, 1)), ProfileBin{0.0, 0.0, 0});
  const double width = c.box.gap / static_cast<double>(bins.size());
  for (std::size_t i = 0; i < bins.size(); ++i) bins[i].x = -0.5 * c.box.gap + (static_cast<double>(i) + 0.5) * width;
  const int last = static_cast<int>(bins.size()) - 1;
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    const int i = std::clamp(static_cast<int>((c.fluid.x[a].x() + 0.5 * c.box.gap) / width), 0, last);
    bins[static_cast<std::size_t>(i)].vz += c.fluid.v[a].z();
    ++bins[static_cast<std::size_t>(i)].count;
  }
  for (ProfileBin& b : bins)
    if (b.count > 0) b.vz /= b.count;
  return bins;
}

double profile_error(const FluidCell& c, const std::function<double(double)>& exact) {
  double num = 0.0, den = 0.0;
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    const double u = exact(c.fluid.x[a].x());
    num += (c.fluid.v[a].z() - u) * (c.fluid.v[a].z() - u);
    den += u * u;
  }
  return std::sqrt(num / den);
}

DensityStats density_stats(const FluidCell& c) {
  DensityStats s{0.0, 0.0};
  for (double rho : c.fluid.rho) {
    const double e = std::abs(rho / c.params.density - 1.0);
    s.mean_abs_error += e;
    s.max_abs_error = std::max(s.max_abs_error, e);
  }
  s.mean_abs_error /= static_cast<double>(std::max<std::size_t>(c.fluid.size(), 1));
  return s;
}

double wall_layer_fraction(const FluidCell& c) {
  const double dx = c.params.spacing, edge = 0.5 * c.box.gap - dx;
  const double lattice = 2.0 * std::round(c.box.ly / dx) * std::round(c.box.lz / dx);
  const auto near = std::count_if(c.fluid.x.begin(), c.fluid.x.end(), [&](const Vec3& x) { return std::abs(x.x()) > edge; });
  return static_cast<double>(near) / lattice;
}

double total_mass(const FluidCell& c) { return c.mass * static_cast<double>(c.fluid.size()); }

Vec3 total_momentum(const FluidCell& c) {
  Vec3 p = Vec3::Zero();
  for (const Vec3& v : c.fluid.v) p += c.mass * v;
  return p;
}

double reynolds_number(const FluidParams& p, const Box& box) {
  const double nu = p.kinematic_viscosity();
  const double v0 = std::max(std::abs(p.shear_rate) * box.gap, std::abs(p.body_force) * box.gap * box.gap / (8.0 * nu));
  return v0 * box.gap / nu;
}

}  // namespace mrf
