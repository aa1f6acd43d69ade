#include "mrf/integrate/implicit_contact.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/pcg.hpp"
#include "parallel_blocks.hpp"

namespace mrf {

namespace {
// rows of the dipole list, and near pairs, a thread takes at least
constexpr std::size_t k_candidate_rows_per_thread = 1000;
constexpr std::size_t k_candidate_pairs_per_thread = 4096;
}  // namespace

const char* to_string(ContactLinearSolver s) {
  switch (s) {
    case ContactLinearSolver::pcg: return "pcg";
    case ContactLinearSolver::pcg_sgs: return "pcg_sgs";
    case ContactLinearSolver::eigen_cg: return "eigen_cg";
    case ContactLinearSolver::eigen_ldlt: return "eigen_ldlt";
  }
  return "?";
}

void contact_candidates(const DemPairLists& lists, const std::vector<Vec3>& x, const WallParticles& walls,
                        const Box& box, double radius, double margin, std::vector<ContactPair>& out) {
  out.clear();
  const double reach = 2.0 * radius + margin, reach2 = reach * reach;
  for (std::size_t i = 0; i < lists.ff.rows(); ++i)
    for (std::uint32_t n = lists.ff.start[i]; n < lists.ff.start[i + 1]; ++n) {
      const std::uint32_t k = lists.ff.k[n];
      if (box.min_image(x[i] - x[k]).squaredNorm() < reach2)
        out.push_back({static_cast<std::uint32_t>(i), k, false});
    }
  for (const auto& [i, k] : lists.fw)
    if (box.min_image(x[i] - walls.x[k]).squaredNorm() < reach2) out.push_back({i, k, true});
}

// Both on threads by blocks (detail::in_blocks: lists joined in block order,
// the serial lists whatever the threads).
void near_pairs(const PairRows& ff, const std::vector<Vec3>& x, const Box& box, double reach,
                std::vector<ContactPair>& out) {
  const double reach2 = reach * reach;
  // rows of a half list: cut for equal shares of its pairs
  detail::in_blocks(
      ff.rows(), k_candidate_rows_per_thread, out,
      [&](std::size_t r0, std::size_t r1, std::vector<ContactPair>& mine) {
        for (std::size_t i = r0; i < r1; ++i)
          for (std::uint32_t n = ff.start[i]; n < ff.start[i + 1]; ++n) {
            const std::uint32_t k = ff.k[n];
            if (box.min_image(x[i] - x[k]).squaredNorm() < reach2)
              mine.push_back({static_cast<std::uint32_t>(i), k, false});
          }
        // each block's rows sorted apart: the blocks hold ascending ranges of i
        std::sort(mine.begin(), mine.end(),
                  [](const ContactPair& a, const ContactPair& b) { return a.i != b.i ? a.i < b.i : a.k < b.k; });
      },
      [&ff](std::size_t, std::size_t blk, std::size_t blocks) { return detail::share_bound(ff.start, blk, blocks); });
}

void contact_candidates(const std::vector<ContactPair>& ff_near, const std::vector<IndexPair>& fw,
                        const std::vector<Vec3>& x, const WallParticles& walls, const Box& box, double radius,
                        double margin, std::vector<ContactPair>& out) {
  const double reach = 2.0 * radius + margin, reach2 = reach * reach;
  detail::in_blocks(ff_near.size(), k_candidate_pairs_per_thread, out,
                    [&](std::size_t lo, std::size_t hi, std::vector<ContactPair>& mine) {
                      for (std::size_t n = lo; n < hi; ++n) {
                        const ContactPair& c = ff_near[n];
                        if (box.min_image(x[c.i] - x[c.k]).squaredNorm() < reach2) mine.push_back(c);
                      }
                    });
  if (detail::block_count(fw.size(), k_candidate_pairs_per_thread) == 1) {
    for (const auto& [i, k] : fw)
      if (box.min_image(x[i] - walls.x[k]).squaredNorm() < reach2) out.push_back({i, k, true});
    return;
  }
  thread_local std::vector<ContactPair> wall;  // the free-wall candidates, by blocks in order
  detail::in_blocks(fw.size(), k_candidate_pairs_per_thread, wall,
                    [&](std::size_t lo, std::size_t hi, std::vector<ContactPair>& mine) {
                      for (std::size_t n = lo; n < hi; ++n) {
                        const auto [i, k] = fw[n];
                        if (box.min_image(x[i] - walls.x[k]).squaredNorm() < reach2) mine.push_back({i, k, true});
                      }
                    });
  out.insert(out.end(), wall.begin(), wall.end());
}

namespace {
// Corrections above this multiple of the Newton tolerance are line-searched.
constexpr double k_line_search_above = 100.0;

Vec3 separation(const ContactPair& c, const std::vector<Vec3>& x, const WallParticles& walls, const Box& box) {
  return box.min_image(x[c.i] - (c.wall ? walls.x[c.k] : x[c.k]));
}
}  // namespace

double contact_forces(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x,
                      const WallParticles& walls, const Box& box, double radius, double hertz_k,
                      std::vector<Vec3>& f) {
  // the overlap of pair c at x and, where it is positive, its Hertz force
  // on i (REFERENCE.md Eq. 2)
  const auto hertz_of = [&](const ContactPair& c, Vec3& fc) {
    const Vec3 r_ik = separation(c, x, walls, box);
    const double r = r_ik.norm(), h = 2.0 * radius - r;
    if (h > 0) fc = (hertz_force(h, hertz_k) / r) * r_ik;
    return h;
  };
  f.assign(x.size(), Vec3::Zero());
  double h_max = 0;
  if (detail::block_count(pairs.size(), k_candidate_pairs_per_thread) == 1) {
    Vec3 fc;
    for (const ContactPair& c : pairs) {
      const double h = hertz_of(c, fc);
      if (h <= 0) continue;
      f[c.i] += fc;
      if (!c.wall) f[c.k] -= fc;
      h_max = std::max(h_max, h);
    }
    return h_max;
  }
  // On threads: the pairs' forces by blocks (most candidates are open), then
  // added in the order of the pairs: the serial sums.
  struct Push {
    Vec3 fc;
    double h;
    std::uint32_t c;
  };
  thread_local std::vector<Push> pushes;  // kept: a list this long is otherwise mapped anew at every call
  detail::in_blocks(pairs.size(), k_candidate_pairs_per_thread, pushes,
                    [&](std::size_t lo, std::size_t hi, std::vector<Push>& mine) {
                      Vec3 fc;
                      for (std::size_t c = lo; c < hi; ++c) {
                        const double h = hertz_of(pairs[c], fc);
                        if (h > 0) mine.push_back({fc, h, static_cast<std::uint32_t>(c)});
                      }
                    });
  for (const Push& p : pushes) {
    const ContactPair& c = pairs[p.c];
    f[c.i] += p.fc;
    if (!c.wall) f[c.k] -= p.fc;
    h_max = std::max(h_max, p.h);
  }
  return h_max;
}

Eigen::Matrix3d hertz_stiffness_block(const Vec3& r_ik, double two_r, double hertz_k) {
  const double r = r_ik.norm(), h = two_r - r;
  if (h <= 0) return Eigen::Matrix3d::Zero();
  const Vec3 n = r_ik / r;
  const Eigen::Matrix3d nn = n * n.transpose();
  const double f_over_r = hertz_force(h, hertz_k) / r;
  return hertz_local_stiffness(h, hertz_k) * nn - f_over_r * (Eigen::Matrix3d::Identity() - nn);
}

double ContactNewton::linearise(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b_step,
                                const std::vector<Vec3>& y, const WallParticles& walls, const Box& box,
                                double radius, double hertz_k, double dt_over_gamma) {
  f_.assign(y.size(), Vec3::Zero());
  local_.assign(y.size(), -1);
  active_.clear();
  blocks_.clear();
  auto compact = [&](std::uint32_t i) {
    if (local_[i] < 0) {
      local_[i] = static_cast<std::int32_t>(active_.size());
      active_.push_back(i);
    }
    return static_cast<std::uint32_t>(local_[i]);
  };
  const double two_r = 2.0 * radius;
  double energy = 0;
  for (const ContactPair& c : pairs) {
    const Vec3 r_ik = separation(c, y, walls, box);
    const double r = r_ik.norm(), h = two_r - r;
    if (h <= 0) continue;
    energy += hertz_energy(h, hertz_k);
    const Vec3 fc = (hertz_force(h, hertz_k) / r) * r_ik;
    f_[c.i] += fc;
    if (!c.wall) f_[c.k] -= fc;
    Block b{compact(c.i), 0, c.wall, dt_over_gamma * hertz_stiffness_block(r_ik, two_r, hertz_k)};
    if (!c.wall) b.c = compact(c.k);
    blocks_.push_back(b);
  }
  diag_inv_.assign(active_.size(), Eigen::Matrix3d::Identity());
  for (const Block& b : blocks_) {
    diag_inv_[b.a] += b.k;
    if (!b.wall) diag_inv_[b.c] += b.k;
  }
  double phi = dt_over_gamma * energy;
  for (std::size_t i = 0; i < y.size(); ++i) phi += 0.5 * (y[i] - b_step[i]).squaredNorm();
  for (auto& d : diag_inv_) d = d.inverse().eval();
  adj_start_.assign(active_.size() + 1, 0);
  for (const Block& b : blocks_)
    if (!b.wall) ++adj_start_[b.a + 1], ++adj_start_[b.c + 1];
  for (std::size_t a = 0; a < active_.size(); ++a) adj_start_[a + 1] += adj_start_[a];
  adj_block_.resize(adj_start_.back());
  std::vector<std::uint32_t> fill(adj_start_.begin(), adj_start_.end() - 1);
  for (std::uint32_t n = 0; n < blocks_.size(); ++n)
    if (!blocks_[n].wall) adj_block_[fill[blocks_[n].a]++] = n, adj_block_[fill[blocks_[n].c]++] = n;
  return phi;
}

// z = M^-1 r. Block Jacobi: M = D. Symmetric block Gauss-Seidel:
// M = (D + L) D^-1 (D + U), with the off-diagonal blocks -K_pair of J.
void ContactNewton::precondition(const std::vector<Vec3>& r, std::vector<Vec3>& z, bool sgs) const {
  const std::size_t n = r.size();
  z.resize(n);
  if (!sgs) {
    for (std::size_t a = 0; a < n; ++a) z[a] = diag_inv_[a] * r[a];
    return;
  }
  auto other = [&](const Block& b, std::size_t a) { return b.a == a ? b.c : b.a; };
  for (std::size_t a = 0; a < n; ++a) {  // forward: (D + L) y = r
    Vec3 s = r[a];
    for (std::uint32_t e = adj_start_[a]; e < adj_start_[a + 1]; ++e) {
      const Block& b = blocks_[adj_block_[e]];
      const std::uint32_t c = other(b, a);
      if (c < a) s += b.k * z[c];
    }
    z[a] = diag_inv_[a] * s;
  }
  for (std::size_t a = n; a-- > 0;) {  // backward: (D + U) z = D y
    Vec3 s = Vec3::Zero();
    for (std::uint32_t e = adj_start_[a]; e < adj_start_[a + 1]; ++e) {
      const Block& b = blocks_[adj_block_[e]];
      const std::uint32_t c = other(b, a);
      if (c > a) s += b.k * z[c];
    }
    z[a] += diag_inv_[a] * s;
  }
}

void ContactNewton::apply(const std::vector<Vec3>& p, std::vector<Vec3>& out) const {
  out = p;
  for (const Block& b : blocks_) {
    if (b.wall) {
      out[b.a] += b.k * p[b.a];
    } else {
      const Vec3 kd = b.k * (p[b.a] - p[b.c]);
      out[b.a] += kd;
      out[b.c] -= kd;
    }
  }
}

// Preconditioned CG on J d = rhs over the particles in contact.
long ContactNewton::solve_pcg(double rtol, bool sgs) {
  return pcg(
      rhs_, rtol, 10 * static_cast<long>(3 * active_.size()) + 10,
      [&](const std::vector<Vec3>& p, std::vector<Vec3>& out) { apply(p, out); },
      [&](const std::vector<Vec3>& r, std::vector<Vec3>& z) { precondition(r, z, sgs); }, d_, cg_);
}

long ContactNewton::solve_eigen(ContactLinearSolver s, double rtol) {
  using SpMat = Eigen::SparseMatrix<double>;
  const Eigen::Index n = static_cast<Eigen::Index>(3 * active_.size());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(n) + 36 * blocks_.size());
  for (Eigen::Index i = 0; i < n; ++i) t.emplace_back(i, i, 1.0);
  auto add = [&](std::uint32_t r, std::uint32_t c, const Eigen::Matrix3d& m, double sign) {
    for (int u = 0; u < 3; ++u)
      for (int v = 0; v < 3; ++v) t.emplace_back(3 * r + u, 3 * c + v, sign * m(u, v));
  };
  for (const Block& b : blocks_) {
    add(b.a, b.a, b.k, 1.0);
    if (b.wall) continue;
    add(b.c, b.c, b.k, 1.0);
    add(b.a, b.c, b.k, -1.0);
    add(b.c, b.a, b.k, -1.0);
  }
  SpMat j(n, n);
  j.setFromTriplets(t.begin(), t.end());
  const Eigen::Map<const Eigen::VectorXd> rhs(rhs_.data()->data(), n);
  d_.assign(active_.size(), Vec3::Zero());
  Eigen::Map<Eigen::VectorXd> d(d_.data()->data(), n);
  if (s == ContactLinearSolver::eigen_ldlt) {
    Eigen::SimplicialLDLT<SpMat> ldlt(j);
    d = ldlt.solve(rhs);
    return 1;
  }
  Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(rtol);
  cg.setMaxIterations(10 * n + 10);
  cg.compute(j);
  d = cg.solve(rhs);
  return static_cast<long>(cg.iterations());
}

// Newton on G = grad Phi, Phi(y) = |y - b|^2 / 2 + (dt/gamma) sum U_hertz: the
// backward Euler step minimises Phi, so a backtracking line search on Phi
// (Armijo) keeps Newton from the overshoots of the Hertz law near contact
// onset, where the stiffness vanishes. Close to convergence the full step is
// taken (Phi then changes below its rounding).
double ContactNewton::merit(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b,
                            const WallParticles& walls, const Box& box, double radius, double hertz_k,
                            double dt_over_gamma, const std::vector<Vec3>& y) const {
  double phi = 0;
  for (std::size_t i = 0; i < y.size(); ++i) phi += 0.5 * (y[i] - b[i]).squaredNorm();
  double u = 0;
  for (const ContactPair& c : pairs) u += hertz_energy(2.0 * radius - separation(c, y, walls, box).norm(), hertz_k);
  return phi + dt_over_gamma * u;
}

NewtonResult ContactNewton::solve(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b,
                                  const WallParticles& walls, const Box& box, double radius, double hertz_k,
                                  double dt_over_gamma, const NewtonOptions& opt, std::vector<Vec3>& y) {
  NewtonResult res;
  const std::size_t n = y.size();
  step_.resize(n);
  for (res.iterations = 1; res.iterations <= opt.max_iterations; ++res.iterations) {
    const double phi0 = linearise(pairs, b, y, walls, box, radius, hertz_k, dt_over_gamma);
    // Particles out of contact: J = I, the correction is -G itself.
    double slope = 0;  // G . d
    for (std::size_t i = 0; i < n; ++i) {
      if (local_[i] >= 0) continue;
      step_[i] = b[i] + dt_over_gamma * f_[i] - y[i];
      slope -= step_[i].squaredNorm();
    }
    if (!active_.empty()) {
      rhs_.resize(active_.size());
      for (std::size_t a = 0; a < active_.size(); ++a) {
        const std::uint32_t i = active_[a];
        rhs_[a] = b[i] + dt_over_gamma * f_[i] - y[i];
      }
      const bool own = opt.solver == ContactLinearSolver::pcg || opt.solver == ContactLinearSolver::pcg_sgs;
      res.linear_iterations += own ? solve_pcg(opt.linear_rtol, opt.solver == ContactLinearSolver::pcg_sgs)
                                   : solve_eigen(opt.solver, opt.linear_rtol);
      for (std::size_t a = 0; a < active_.size(); ++a) {
        step_[active_[a]] = d_[a];
        slope -= rhs_[a].dot(d_[a]);
      }
    }
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (step_[i].norm() > worst) worst = step_[i].norm(), res.worst = static_cast<std::uint32_t>(i);
    res.last_correction = worst;
    if (!std::isfinite(worst)) return res;
    double alpha = 1;
    if (worst > k_line_search_above * opt.tol && slope < 0) {
      trial_ = y;
      for (; alpha > 1e-3; alpha *= 0.5) {
        for (std::size_t i = 0; i < n; ++i) trial_[i] = y[i] + alpha * step_[i];
        if (merit(pairs, b, walls, box, radius, hertz_k, dt_over_gamma, trial_) <= phi0 + 1e-4 * alpha * slope) break;
      }
    }
    for (std::size_t i = 0; i < n; ++i) y[i] += alpha * step_[i];
    if (alpha == 1 && worst <= opt.tol) {
      res.converged = true;
      return res;
    }
  }
  res.iterations = opt.max_iterations;
  return res;
}

}  // namespace mrf
