#include "mrf/fluid/implicit_fluid.hpp"

#include <cmath>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/fluid/viscosity.hpp"
#include "mrf/integrate/pcg.hpp"

#include "parallel_blocks.hpp"
#include "runs.hpp"

namespace mrf {

namespace {
// the runs of rows of one a (rows come by a); no row of a's run reaches
// out[a] through b (b != a), so holding out[a] over the run is bit for bit
// the plain scatter
template <class Rows, class Run>
void by_rows(const Rows& rows, Run run) {
  detail::for_each_run(rows, [](const auto& e) { return e.a; }, run);
}

// Below this many pairs the products run serially (a product of the paper
// cell's 900 SPH particles has about 33k).
constexpr std::size_t k_rows_per_thread = 4096;
}  // namespace

const char* to_string(SphImplicit s) {
  switch (s) {
    case SphImplicit::none: return "explicit";
    case SphImplicit::viscosity: return "implicit_viscosity";
    default: return "implicit";
  }
}

ImplicitFluidSystem::ImplicitFluidSystem(const FluidCell& c, double dt, SphImplicit terms)
    : c_(c), dt_(dt), pressure_(terms == SphImplicit::pressure_viscosity) {
  const std::size_t n = c.fluid.size();
  const auto& rho = c.fluid.rho;
  const auto& pairs = c.pairs.fluid_fluid;
  const auto& wall_pairs = c.pairs.fluid_wall;
  rows_.resize(pairs.size());
  kw_.resize(wall_pairs.size());
  vdiag_.assign(n, 1.0);
  const double scale = c.mass * c.density_scale;
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const SphPair& pr = pairs[e];
    const double k = -dt * morris_weight(pr.r, c.h, c.mass, effective_viscosity(c), rho[pr.a], rho[pr.b]);
    rows_[e] = {pr.a, pr.b, k, pressure_ ? Vec3(scale * kernel_dwdr_over_r(pr.r, c.h) * pr.r_ab) : Vec3::Zero()};
    vdiag_[pr.a] += k;
    vdiag_[pr.b] += k;
  }
  for (std::size_t e = 0; e < wall_pairs.size(); ++e) {
    kw_[e] = -dt * wall_viscous_weight(c, wall_pairs[e]);
    vdiag_[wall_pairs[e].a] += kw_[e];
  }
  diag_.resize(n);
  for (std::size_t a = 0; a < n; ++a) diag_[a] = Vec3::Constant(vdiag_[a]);
  // On threads the products gather: per particle a copy of each row it is
  // an end of, in row order, seen from its side (the other end; g_ab
  // signed, so that g . (x_a - x_other) is the row's g . (x_a - x_b) for
  // either end): each particle's sum takes its terms in the order the
  // serial scatter adds them, the same result bit for bit.
  if (detail::block_count(rows_.size(), k_rows_per_thread) > 1) {
    inc_start_.assign(n + 1, 0);
    for (const Row& e : rows_) ++inc_start_[e.a + 1], ++inc_start_[e.b + 1];
    for (std::size_t a = 0; a < n; ++a) inc_start_[a + 1] += inc_start_[a];
    inc_.resize(inc_start_[n]);
    std::vector<std::uint32_t> next(inc_start_.begin(), inc_start_.end() - 1);
    for (const Row& e : rows_) {
      inc_[next[e.a]++] = {e.a, e.b, e.k, e.g};
      inc_[next[e.b]++] = {e.b, e.a, e.k, -e.g};
    }
  }
  if (!pressure_) return;
  tw_.assign(n, Vec3::Zero());
  d0_.assign(n, 0.0);
  for (const SphPair& pr : wall_pairs) {
    const Vec3 g = scale * kernel_dwdr_over_r(pr.r, c.h) * pr.r_ab;
    tw_[pr.a] += g;
    d0_[pr.a] -= g.dot(c.wall.v[pr.b]);
  }
  q_.resize(n);
  const bool porous = !c.fluid.eps.empty();
  for (std::size_t a = 0; a < n; ++a) {
    const double k = c.c0 * c.c0 / (porous ? c.fluid.eps[a] : 1.0);
    q_[a] = dt * dt * k / (c.density_scale * rho[a] * rho[a]);
  }
  // diagonal of D^T Q D: Q_a T_a T_a^T + sum_b Q_b g_ab g_ab^T, T_a the
  // derivative of (D v)_a by v_a (component-wise, for the preconditioner)
  std::vector<Vec3> t(tw_);
  for (const Row& e : rows_) {
    t[e.a] += e.g;
    t[e.b] -= e.g;
    const Vec3 g2 = e.g.cwiseProduct(e.g);
    diag_[e.a] += q_[e.b] * g2;
    diag_[e.b] += q_[e.a] * g2;
  }
  for (std::size_t a = 0; a < n; ++a) diag_[a] += q_[a] * t[a].cwiseProduct(t[a]);
}

// s = D x (+ d0)
void ImplicitFluidSystem::divergence(const std::vector<Vec3>& x, bool with_d0, std::vector<double>& s) const {
  s.resize(x.size());
  for (std::size_t a = 0; a < x.size(); ++a) s[a] = tw_[a].dot(x[a]) + (with_d0 ? d0_[a] : 0.0);
  for (const Row& e : rows_) {
    const double d = e.g.dot(x[e.a] - x[e.b]);
    s[e.a] += d;
    s[e.b] += d;
  }
}

std::vector<double> ImplicitFluidSystem::density_change(const std::vector<Vec3>& v) const {
  std::vector<double> d(v.size(), 0.0);
  if (!pressure_) return d;
  divergence(v, true, d);
  for (double& x : d) x *= dt_;
  return d;
}

// out += dt^2 S1 D^T Q (D x + with_d0 d0); s_ keeps Q (D x + d0) dt^2 S1
void ImplicitFluidSystem::add_pressure(const std::vector<Vec3>& x, bool with_d0, std::vector<Vec3>& out) const {
  divergence(x, with_d0, s_);
  scatter_pressure(out);
}

// s_ *= Q, out += D^T s_
void ImplicitFluidSystem::scatter_pressure(std::vector<Vec3>& out) const {
  const std::size_t n = out.size();
  if (!inc_.empty()) {
    detail::for_each_index(n, 1, [&](std::size_t a) { s_[a] *= q_[a]; });
    detail::for_each_index(n, 1, [&](std::size_t a) {
      Vec3 o = out[a] + s_[a] * tw_[a];
      for (std::uint32_t k = inc_start_[a]; k < inc_start_[a + 1]; ++k) o += (s_[a] + s_[inc_[k].b]) * inc_[k].g;
      out[a] = o;
    });
    return;
  }
  for (std::size_t a = 0; a < n; ++a) {
    s_[a] *= q_[a];
    out[a] += s_[a] * tw_[a];
  }
  by_rows(rows_, [&](std::uint32_t a, std::size_t first, std::size_t last) {
    Vec3 out_a = out[a];
    for (std::size_t r = first; r < last; ++r) {
      const Row& e = rows_[r];
      const Vec3 f = (s_[a] + s_[e.b]) * e.g;
      out_a += f;
      out[e.b] -= f;
    }
    out[a] = out_a;
  });
}

void ImplicitFluidSystem::apply(const std::vector<Vec3>& x, std::vector<Vec3>& out) const {
  const std::size_t n = x.size();
  out.resize(n);
  if (!inc_.empty()) {
    if (pressure_) s_.resize(n);
    // the viscous product (and the divergence) gathered per particle
    detail::for_each_index(n, 1, [&](std::size_t a) {
      Vec3 o = vdiag_[a] * x[a];
      double s = pressure_ ? tw_[a].dot(x[a]) : 0.0;
      for (std::uint32_t k = inc_start_[a]; k < inc_start_[a + 1]; ++k) {
        const Row& e = inc_[k];
        o -= e.k * x[e.b];
        if (pressure_) s += e.g.dot(x[a] - x[e.b]);
      }
      out[a] = o;
      if (pressure_) s_[a] = s;
    });
    if (pressure_) scatter_pressure(out);
    return;
  }
  for (std::size_t a = 0; a < n; ++a) out[a] = vdiag_[a] * x[a];
  if (!pressure_) {
    by_rows(rows_, [&](std::uint32_t a, std::size_t first, std::size_t last) {
      Vec3 out_a = out[a];
      for (std::size_t r = first; r < last; ++r) {
        const Row& e = rows_[r];
        out_a -= e.k * x[e.b];
        out[e.b] -= e.k * x[a];
      }
      out[a] = out_a;
    });
    return;
  }
  // the viscous product and the divergence D x in one pass over the pairs
  // (each sum in the same order as two passes), then the pressure's
  s_.resize(n);
  for (std::size_t a = 0; a < n; ++a) s_[a] = tw_[a].dot(x[a]);
  by_rows(rows_, [&](std::uint32_t a, std::size_t first, std::size_t last) {
    Vec3 out_a = out[a];
    double s_a = s_[a];
    for (std::size_t r = first; r < last; ++r) {
      const Row& e = rows_[r];
      out_a -= e.k * x[e.b];
      out[e.b] -= e.k * x[a];
      const double d = e.g.dot(x[a] - x[e.b]);
      s_a += d;
      s_[e.b] += d;
    }
    out[a] = out_a;
    s_[a] = s_a;
  });
  scatter_pressure(out);
}

std::vector<Vec3> ImplicitFluidSystem::rhs(const std::vector<Vec3>& v_star) const {
  std::vector<Vec3> r(v_star);
  for (std::size_t e = 0; e < kw_.size(); ++e) r[c_.pairs.fluid_wall[e].a] += kw_[e] * c_.wall.v[c_.pairs.fluid_wall[e].b];
  if (pressure_) {
    std::vector<Vec3> known(r.size(), Vec3::Zero());
    add_pressure(std::vector<Vec3>(r.size(), Vec3::Zero()), true, known);
    for (std::size_t a = 0; a < r.size(); ++a) r[a] -= known[a];
  }
  return r;
}

Vec3 ImplicitFluidSystem::wall_push(const std::vector<Vec3>& v) const {
  // viscous dt K beta (v_a - v_w) = -kw (v_a - v_w); pressure -s_a T_a, s = Q (D v + d0)
  Vec3 push = Vec3::Zero();
  for (std::size_t e = 0; e < kw_.size(); ++e)
    push -= kw_[e] * (v[c_.pairs.fluid_wall[e].a] - c_.wall.v[c_.pairs.fluid_wall[e].b]);
  if (pressure_) {
    std::vector<Vec3> scratch(v.size(), Vec3::Zero());
    add_pressure(v, true, scratch);
    for (std::size_t a = 0; a < v.size(); ++a) push -= s_[a] * tw_[a];
  }
  return push;
}

Eigen::Matrix3d ImplicitFluidSystem::uniform_response() const {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity() * static_cast<double>(c_.fluid.size());
  for (double k : kw_) m.diagonal().array() += k;
  if (pressure_)
    for (std::size_t a = 0; a < tw_.size(); ++a) m += q_[a] * tw_[a] * tw_[a].transpose();
  return m;
}

ImplicitSolveStats solve_implicit_fluid(const FluidCell& c, double dt, SphImplicit terms, std::vector<Vec3>& v) {
  // One PCG on the three velocity components together, for the correction
  // to the predictor v, Jacobi-preconditioned.
  const std::size_t n = c.fluid.size();
  const ImplicitFluidSystem sys(c, dt, terms);
  const std::vector<Vec3> rhs = sys.rhs(v);
  const std::vector<Vec3>& diag = sys.diagonal();
  auto apply = [&](const std::vector<Vec3>& x, std::vector<Vec3>& out) { sys.apply(x, out); };
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
          for (std::size_t a = 0; a < n; ++a) z[a] = r[a].cwiseQuotient(diag[a]);
        },
        d, cg));
    stats.residual = std::sqrt(vector_dot(cg.r, cg.r)) / rn;
    if (!(stats.residual <= c.params.cg_tolerance)) {
      std::ostringstream m;
      m << "SPH implicit " << (terms == SphImplicit::pressure_viscosity ? "pressure and viscosity" : "viscosity")
        << ": CG did not converge at step " << c.steps << " (t = " << c.time << " s, dt = " << dt
        << " s, relative residual " << stats.residual << ")";
      throw NumericalError(m.str());
    }
    for (std::size_t a = 0; a < n; ++a) v[a] += d[a];
  }
  // momentum: sum_a (rhs - A v)_a = 0 by a uniform shift u, (sum_a A 1) u = sum r
  apply(v, av);
  Vec3 r_sum = Vec3::Zero();
  for (std::size_t a = 0; a < n; ++a) r_sum += rhs[a] - av[a];
  const Vec3 u = sys.uniform_response().ldlt().solve(r_sum);
  for (Vec3& x : v) x += u;
  stats.wall_dv = sys.wall_push(v);
  return stats;
}

}  // namespace mrf
