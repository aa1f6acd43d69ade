#include "mrf/fluid/viscosity.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <cmath>
#include <sstream>

#include "mrf/error.hpp"

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
  const auto n = static_cast<Eigen::Index>(c.fluid.size());
  const auto& rho = c.fluid.rho;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(2 * c.pairs.fluid_fluid.size() + c.fluid.size());
  Eigen::VectorXd diag = Eigen::VectorXd::Ones(n);
  Eigen::MatrixX3d rhs(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) rhs.row(i) = v[i].transpose();
  for (const SphPair& pr : c.pairs.fluid_fluid) {
    const double k = -dt * morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), rho[pr.a], rho[pr.b]);
    t.emplace_back(pr.a, pr.b, -k);
    t.emplace_back(pr.b, pr.a, -k);
    diag[pr.a] += k;
    diag[pr.b] += k;
  }
  for (const SphPair& pr : c.pairs.fluid_wall) {
    const double k = -dt * wall_weight(c, pr);
    diag[pr.a] += k;
    rhs.row(pr.a) += k * c.wall.v[pr.b].transpose();
  }
  for (Eigen::Index i = 0; i < n; ++i) t.emplace_back(i, i, diag[i]);
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(t.begin(), t.end());

  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(c.params.cg_tolerance);
  cg.compute(m);
  ImplicitSolveStats stats;
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd guess(n);
    for (Eigen::Index i = 0; i < n; ++i) guess[i] = v[i][d];
    const Eigen::VectorXd x = cg.solveWithGuess(rhs.col(d), guess);
    if (cg.info() != Eigen::Success) {
      std::ostringstream s;
      s << "SPH implicit viscosity: CG did not converge for velocity component " << d << " at step "
        << c.steps << " (t = " << c.time << " s, dt = " << dt << " s, residual " << cg.error() << ")";
      throw NumericalError(s.str());
    }
    for (Eigen::Index i = 0; i < n; ++i) v[i][d] = x[i];
    stats.iterations = std::max(stats.iterations, static_cast<int>(cg.iterations()));
    stats.residual = std::max(stats.residual, cg.error());
  }
  return stats;
}

}  // namespace mrf
