#include "mrf/fluid/viscosity.hpp"

#include <cmath>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/integrate/pcg.hpp"

namespace mrf {

namespace {

// K_aB beta_aB of a fluid-wall pair: the wall term is K beta (v_a - v_w).
double wall_weight(const FluidCell& c, const SphPair& pr) {
  const int side = c.wall.side[pr.b];
  const double beta = morris_wall_factor(c.wall.depth[pr.b], wall_distance(c, c.fluid.x[pr.a], side),
                                         0.5 * c.params.spacing);
  return beta * morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), c.fluid.rho[pr.a], c.wall.rho[pr.b]);
}

}  // namespace

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
  return wall_weight(c, pr) * (c.fluid.v[pr.a] - c.wall.v[pr.b]);
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

ImplicitSolveStats solve_implicit_viscosity(const FluidCell& c, double dt, std::vector<Vec3>& v) {
  // Matrix-free: the Morris weights of the fluid pairs once, then one PCG on
  // the three velocity components together (the operator acts alike on
  // each), for the correction to the predictor v, Jacobi-preconditioned.
  const std::size_t n = c.fluid.size();
  const auto& rho = c.fluid.rho;
  const auto& pairs = c.pairs.fluid_fluid;
  std::vector<double> k(pairs.size()), diag(n, 1.0);
  std::vector<Vec3> rhs(v);
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const SphPair& pr = pairs[e];
    k[e] = -dt * morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), rho[pr.a], rho[pr.b]);
    diag[pr.a] += k[e];
    diag[pr.b] += k[e];
  }
  for (const SphPair& pr : c.pairs.fluid_wall) {
    const double kw = -dt * wall_weight(c, pr);
    diag[pr.a] += kw;
    rhs[pr.a] += kw * c.wall.v[pr.b];
  }
  auto apply = [&](const std::vector<Vec3>& x, std::vector<Vec3>& out) {
    out.resize(n);
    for (std::size_t a = 0; a < n; ++a) out[a] = diag[a] * x[a];
    for (std::size_t e = 0; e < pairs.size(); ++e) {
      out[pairs[e].a] -= k[e] * x[pairs[e].b];
      out[pairs[e].b] -= k[e] * x[pairs[e].a];
    }
  };
  std::vector<Vec3> av, b(n), d;
  apply(v, av);
  for (std::size_t a = 0; a < n; ++a) b[a] = rhs[a] - av[a];
  // stop where |residual| <= cg_tolerance |rhs|, as for a solve from zero
  const double bn = std::sqrt(vector_dot(b, b)), rn = std::sqrt(vector_dot(rhs, rhs));
  ImplicitSolveStats stats;
  if (bn > c.params.cg_tolerance * rn) {
    PcgScratch<Vec3> cg;
    const double rtol = c.params.cg_tolerance * rn / bn;
    stats.iterations = static_cast<int>(pcg(
        b, rtol, 10 * static_cast<long>(n) + 10, apply,
        [&](const std::vector<Vec3>& r, std::vector<Vec3>& z) {
          z.resize(n);
          for (std::size_t a = 0; a < n; ++a) z[a] = r[a] / diag[a];
        },
        d, cg));
    stats.residual = std::sqrt(vector_dot(cg.r, cg.r)) / rn;
    if (!(stats.residual <= c.params.cg_tolerance)) {
      std::ostringstream s;
      s << "SPH implicit viscosity: CG did not converge at step " << c.steps << " (t = " << c.time
        << " s, dt = " << dt << " s, relative residual " << stats.residual << ")";
      throw NumericalError(s.str());
    }
    for (std::size_t a = 0; a < n; ++a) v[a] += d[a];
  }
  return stats;
}

}  // namespace mrf
