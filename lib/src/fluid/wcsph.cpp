#include "mrf/fluid/wcsph.hpp"

#include "mrf/forces/drag.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "mrf/error.hpp"

namespace mrf {

namespace {

// rho_a = (1/S1) sum_b m W_ab (see FluidCell::density_scale).
void summation_density(FluidCell& c) {
  const double mw = c.mass * c.density_scale;
  auto& rho = c.fluid.rho;
  rho.assign(c.fluid.size(), mw * kernel_w(0.0, c.h));
  for (const SphPair& pr : c.pairs.fluid_fluid) {
    const double w = mw * kernel_w(pr.r, c.h);
    rho[pr.a] += w;
    rho[pr.b] += w;
  }
  for (const SphPair& pr : c.pairs.fluid_wall) rho[pr.a] += mw * kernel_w(pr.r, c.h);
}

void wall_pressure(FluidCell& c) {
  const std::size_t nw = c.wall.size();
  const bool porous = !c.fluid.eps.empty();
  std::vector<double> sum_pw(nw, 0.0), sum_grw(nw, 0.0), sum_w(nw, 0.0), sum_ew(porous ? nw : 0, 0.0);
  const Vec3 g(0.0, 0.0, c.params.body_force);
  for (const SphPair& pr : c.pairs.fluid_wall) {
    const double w = kernel_w(pr.r, c.h);
    sum_pw[pr.b] += c.fluid.p[pr.a] * w;
    sum_grw[pr.b] += c.fluid.rho[pr.a] * g.dot(-pr.r_ab) * w;  // r_wf = -r_ab
    sum_w[pr.b] += w;
    if (porous) sum_ew[pr.b] += c.fluid.eps[pr.a] * w;
  }
  for (std::size_t b = 0; b < nw; ++b) {
    c.wall.p[b] = adami_wall_pressure(sum_pw[b], sum_grw[b], sum_w[b]);
    // In the averaged equations the porosity field moves faster than the
    // fluid particles rearrange, and the fluid next to a wall can go into
    // tension; a wall extrapolating that tension pulls SPH particles through
    // it. The wall does not adhere: its pressure is kept >= 0, so fluid in
    // tension retracts toward the bulk instead.
    if (porous) c.wall.p[b] = std::max(c.wall.p[b], 0.0);
    c.wall.rho[b] = eos_density(c.wall.p[b], c.params.density, c.c0);
    if (porous && sum_w[b] > 0.0) c.wall.rho[b] *= sum_ew[b] / sum_w[b];
  }
}

void drift(FluidCell& c, double dt) {
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    c.fluid.x[a] += dt * c.fluid.v[a];
    c.box.wrap(c.fluid.x[a]);
  }
  for (std::size_t b = 0; b < c.wall.size(); ++b) {
    c.wall.x[b] += dt * c.wall.v[b];
    c.box.wrap(c.wall.x[b]);
  }
}

// Throws on a non-finite state or a fluid particle beyond a wall plane; run
// before the step too, so a value corrupted from outside is reported at its
// own particle before the pair sums spread it to the neighbours.
void check_state(const FluidCell& c, const char* when) {
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    const Vec3& x = c.fluid.x[a];
    const bool finite = x.allFinite() && c.fluid.v[a].allFinite();
    if (finite && std::abs(x.x()) < 0.5 * c.box.gap) continue;
    std::ostringstream s;
    s << "SPH: fluid particle " << a << (finite ? " crossed a wall plane" : " has a non-finite position or velocity")
      << " " << when << " step " << c.steps << " (t = " << c.time << " s): x = (" << x.transpose()
      << ") m, v = (" << c.fluid.v[a].transpose() << ") m/s";
    throw NumericalError(s.str());
  }
}

void finish_step(FluidCell& c, double dt) {
  drift(c, dt);
  c.time += dt;
  check_state(c, "after");
  ++c.steps;
  refresh(c);
}

}  // namespace

void refresh(FluidCell& c) {
  c.pairs = find_pairs(c);
  summation_density(c);
  update_pressures(c);
}

void refresh(FluidCell& c, SphPairCache& cache) {
  update_pairs(c, cache);
  summation_density(c);
  update_pressures(c);
}

void update_pressures(FluidCell& c) {
  c.fluid.p.resize(c.fluid.size());
  const bool porous = !c.fluid.eps.empty(), labelled = !c.fluid.rest_density.empty();
  for (std::size_t a = 0; a < c.fluid.size(); ++a) {
    const double rho = porous ? c.fluid.rho[a] / c.fluid.eps[a] : c.fluid.rho[a];
    c.fluid.p[a] = eos_pressure(rho, labelled ? c.fluid.rest_density[a] : c.params.density, c.c0);
  }
  wall_pressure(c);
}

void add_pressure_acceleration(const FluidCell& c, std::vector<Vec3>& a) {
  const auto& f = c.fluid;
  for (const SphPair& pr : c.pairs.fluid_fluid) {
    const Vec3 d = pressure_pair_acceleration(c.mass, f.p[pr.a], f.rho[pr.a], f.p[pr.b], f.rho[pr.b],
                                              pr.r_ab, pr.r, c.h);
    a[pr.a] += d;
    a[pr.b] -= d;
  }
  for (const SphPair& pr : c.pairs.fluid_wall)
    a[pr.a] += pressure_pair_acceleration(c.mass, f.p[pr.a], f.rho[pr.a], c.wall.p[pr.b], c.wall.rho[pr.b],
                                          pr.r_ab, pr.r, c.h);
}

std::vector<Vec3> external_acceleration(const FluidCell& c) {
  std::vector<Vec3> a(c.fluid.a_ext);
  const Vec3 g(0.0, 0.0, c.params.body_force);
  for (Vec3& ai : a) ai += g;
  return a;
}

void step(FluidCell& c, double dt) {
  check_state(c, "before");
  std::vector<Vec3> a = external_acceleration(c);
  add_pressure_acceleration(c, a);
  add_viscous_acceleration(c, a);
  for (std::size_t i = 0; i < a.size(); ++i) c.fluid.v[i] += dt * a[i];
  finish_step(c, dt);
}

ImplicitSolveStats step_implicit(FluidCell& c, double dt, SphImplicit terms) {
  check_state(c, "before");
  std::vector<Vec3> a = external_acceleration(c);
  add_pressure_acceleration(c, a);
  std::vector<Vec3> v(c.fluid.v);
  for (std::size_t i = 0; i < a.size(); ++i) v[i] += dt * a[i];
  const ImplicitSolveStats stats = solve_implicit_fluid(c, dt, terms, v);
  c.fluid.v = std::move(v);
  finish_step(c, dt);
  return stats;
}

double viscous_limit(const FluidCell& c) { return 0.125 * c.h * c.h / c.params.kinematic_viscosity(); }

std::vector<StabilityLimit> stability_limits(const FluidCell& c, SphImplicit implicit) {
  double vmax = wall_speed(c.params.shear_rate, c.box.gap);
  for (const Vec3& v : c.fluid.v) vmax = std::max(vmax, v.norm());
  double fmax = 0.0;
  for (const Vec3& f : external_acceleration(c)) fmax = std::max(fmax, f.norm());
  std::vector<StabilityLimit> out;
  if (implicit == SphImplicit::pressure_viscosity)
    out.push_back({"advection", 0.25 * c.h / vmax, "0.25 h/|v|max (sound implicit)"});
  else
    out.push_back({"cfl", 0.25 * c.h / (c.c0 + vmax), "0.25 h/(c0 + |v|max), Morris et al. 1997"});
  if (implicit == SphImplicit::none) out.push_back({"viscous", viscous_limit(c), "0.125 h^2/nu, Morris et al. 1997"});
  if (fmax > 0.0) out.push_back({"force", 0.25 * std::sqrt(c.h / fmax), "0.25 sqrt(h/|f|max), Morris et al. 1997"});
  return out;
}

void check_time_step(const FluidCell& c, double dt, SphImplicit implicit) {
  if (!(dt > 0) || !std::isfinite(dt)) {
    std::ostringstream s;
    s << dt;
    throw InputError("numerics.dt", s.str(), "", "must be positive and finite");
  }
  for (const StabilityLimit& l : stability_limits(c, implicit))
    if (dt > l.dt) {
      std::ostringstream s, v;
      v << dt;
      s << "exceeds the SPH stability limit '" << l.name << "' = " << l.dt << " s";
      throw InputError("numerics.dt", v.str(), "", s.str());
    }
}

}  // namespace mrf
