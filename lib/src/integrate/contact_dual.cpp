#include "mrf/integrate/contact_dual.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/forces/hertz.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "parallel_blocks.hpp"

namespace mrf {

namespace {
Vec3 pair_vector(const ContactPair& c, const std::vector<Vec3>& x, const WallParticles& walls, const MinImageYZ& mi) {
  Vec3 d = x[c.i] - (c.wall ? walls.x[c.k] : x[c.k]);
  d.y() = mi.wrap_y(d.y());
  d.z() = mi.wrap_z(d.z());
  return d;
}

// Items (pairs, contacts, spheres) a thread takes at least in the solve's
// passes; fewer run on one thread.
constexpr std::size_t k_dual_per_thread = 1024;

}  // namespace

// act_particles_, and where more than one thread runs the passes over the
// spheres (or IC(0) is assembled), per sphere its entries in act_ ascending,
// each with the contact's normal signed as G puts it on the sphere (+n at
// i, -n at k). A pass by sphere adds each sphere's terms in the order of the
// serial pass over the contacts (m (q (-n)) = -(m (q n)) exactly), so the
// result is the same bit for bit whatever the number of threads; on one
// thread the pass over the contacts runs, which is faster there. Built by
// blocks of contacts on threads: each block counts its entries per sphere,
// the counts become each block's first slot per sphere (block 0's first),
// and each block fills its own slots, so every sphere's entries come in
// ascending a whatever the number of threads.
void ContactDual::index_spheres(const std::vector<ContactPair>& pairs) {
  const std::size_t n = disp_.size(), m = act_.size();
  const int blocks = detail::block_count(m, k_dual_per_thread);
  row_fill_.resize(static_cast<std::size_t>(blocks));
  detail::for_blocks(m, blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
    std::vector<std::uint32_t>& count = row_fill_[blk];
    count.assign(n, 0);
    for (std::size_t a = lo; a < hi; ++a) {
      const ContactPair& pc = pairs[act_[a]];
      ++count[pc.i];
      if (!pc.wall) ++count[pc.k];
    }
  });
  row_start_.resize(n + 1);
  row_start_[0] = 0;
  act_particles_.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    std::uint32_t slot = row_start_[i];
    for (std::vector<std::uint32_t>& count : row_fill_) {  // counts -> each block's first slot
      const std::uint32_t c = count[i];
      count[i] = slot;
      slot += c;
    }
    if (slot > row_start_[i]) act_particles_.push_back(i);
    row_start_[i + 1] = slot;
  }
  sphere_blocks_ = detail::block_count(act_particles_.size(), k_dual_per_thread);
  if (sphere_blocks_ == 1 && !uses_ic0()) return;
  row_entry_.resize(row_start_[n]);
  detail::for_blocks(m, blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
    std::vector<std::uint32_t>& next = row_fill_[blk];
    for (std::size_t a = lo; a < hi; ++a) {
      const std::uint32_t c = act_[a];
      const ContactPair& pc = pairs[c];
      row_entry_[next[pc.i]++] = {n_[c], static_cast<std::uint32_t>(a)};
      if (!pc.wall) row_entry_[next[pc.k]++] = {-n_[c], static_cast<std::uint32_t>(a)};
    }
  });
}

bool ContactDual::uses_ic0() const {
  return precond_ == Preconditioner::incomplete_cholesky || (precond_ == Preconditioner::automatic && coupled_);
}

void ContactDual::move(const std::vector<ContactPair>& pairs, const std::vector<double>& q, bool by_pair,
                       std::vector<Vec3>& y) {
  const std::vector<double>& mob = *mob_;
  if (coupled_) s_.assign(y.size(), Vec3::Zero());
  if (sphere_blocks_ == 1) {
    for (std::size_t a = 0; a < act_.size(); ++a) {
      const std::uint32_t c = act_[a];
      const double v = by_pair ? q[c] : q[a];
      if (v == 0) continue;
      const ContactPair& pc = pairs[c];
      const Vec3 f = v * n_[c];
      y[pc.i] += mob[pc.i] * f;
      if (!pc.wall) y[pc.k] -= mob[pc.k] * f;
      if (coupled_) {
        s_[pc.i] += f;
        if (!pc.wall) s_[pc.k] -= f;
      }
    }
  } else {
    detail::for_blocks(act_particles_.size(), sphere_blocks_, [&](std::size_t, std::size_t lo, std::size_t hi) {
      for (std::size_t t = lo; t < hi; ++t) {
        const std::uint32_t i = act_particles_[t];
        Vec3 yi = y[i], si = Vec3::Zero();
        for (std::uint32_t e = row_start_[i]; e < row_start_[i + 1]; ++e) {
          const SphereEntry& en = row_entry_[e];
          const double v = by_pair ? q[act_[en.a]] : q[en.a];
          if (v == 0) continue;
          const Vec3 f = v * en.sn;
          yi += mob[i] * f;
          si += f;
        }
        y[i] = yi;
        if (coupled_) s_[i] = si;
      }
    });
  }
  if (coupled_) coupled_->add(s_, coupled_scale_, y);
}

void ContactDual::add_forces(const std::vector<ContactPair>& pairs, std::vector<Vec3>& f) const {
  for (std::size_t c = 0; c < pairs.size() && c < lambda_.size(); ++c) {
    if (lambda_[c] <= 0) continue;
    const Vec3 g = lambda_[c] * n_[c];
    f[pairs[c].i] += g;
    if (!pairs[c].wall) f[pairs[c].k] -= g;
  }
}

// (A + C) p on the active set: A = G^T M G, C diagonal. Only the spheres of
// active contacts are read back, so only their rows of M G p are formed.
void ContactDual::apply(const std::vector<ContactPair>& pairs, const std::vector<double>& p,
                        std::vector<double>& out) {
  const std::vector<double>& mob = *mob_;
  const std::size_t m = act_.size(), ns = act_particles_.size();
  out.resize(m);
  const int contact_blocks = detail::block_count(m, k_dual_per_thread);
  if (!coupled_) {  // the packed copy of this linear solve (solve_cg): no indirection, no branch
    if (sphere_blocks_ == 1)
      packed_scatter(p.data());
    else
      detail::for_blocks(ns, sphere_blocks_,
                         [&](std::size_t, std::size_t lo, std::size_t hi) { packed_gather(p.data(), lo, hi); });
    detail::for_blocks(m, contact_blocks,
                       [&](std::size_t, std::size_t lo, std::size_t hi) { packed_product(p.data(), out.data(), lo, hi); });
    return;
  }
  s_.assign(disp_.size(), Vec3::Zero());
  if (sphere_blocks_ == 1) {
    for (auto i : act_particles_) disp_[i].setZero();
    for (std::size_t a = 0; a < m; ++a) {
      const ContactPair& c = pairs[act_[a]];
      const Vec3 g = p[a] * n_[act_[a]];
      disp_[c.i] += mob[c.i] * g;
      if (!c.wall) disp_[c.k] -= mob[c.k] * g;
      s_[c.i] += g;
      if (!c.wall) s_[c.k] -= g;
    }
  } else {
    detail::for_blocks(ns, sphere_blocks_, [&](std::size_t, std::size_t lo, std::size_t hi) {
      for (std::size_t t = lo; t < hi; ++t) {
        const std::uint32_t i = act_particles_[t];
        Vec3 d = Vec3::Zero(), si = Vec3::Zero();
        for (std::uint32_t e = row_start_[i]; e < row_start_[i + 1]; ++e) {
          const SphereEntry& en = row_entry_[e];
          const Vec3 g = p[en.a] * en.sn;
          d += mob[i] * g;
          si += g;
        }
        disp_[i] = d;
        s_[i] = si;
      }
    });
  }
  coupled_->add_jacobian(s_, coupled_scale_, disp_, &act_particles_);
  detail::for_blocks(m, contact_blocks, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t a = lo; a < hi; ++a) {
      const std::uint32_t e = act_[a];
      const ContactPair& c = pairs[e];
      const Vec3 rel = c.wall ? disp_[c.i] : Vec3(disp_[c.i] - disp_[c.k]);
      out[a] = n_[e].dot(rel) + comp_[e] * p[a];
    }
  });
}

long ContactDual::solve_cg(const std::vector<ContactPair>& pairs, double rtol) {
  const std::size_t m = act_.size();
  const std::vector<double>& mob = *mob_;
  diag_.resize(m);
  r_.resize(m);
  // Without a coupled mobility, also what apply reads, in the order it reads
  // it; a wall pair's far end is the spare row n of pdisp_.
  const auto spare = static_cast<std::uint32_t>(disp_.size());
  if (!coupled_) {
    pdisp_.resize(disp_.size() + 1);
    pdisp_[spare].setZero();
    packed_.resize(m);
  }
  detail::for_blocks(m, detail::block_count(m, k_dual_per_thread), [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t a = lo; a < hi; ++a) {
      const std::uint32_t e = act_[a];
      const ContactPair& c = pairs[e];
      const double mob_k = c.wall ? 0.0 : mob[c.k];
      diag_[a] = mob[c.i] + mob_k + comp_[e] + (coupled_ ? crel_[e] : 0.0);
      r_[a] = rhs_[e];
      if (!coupled_) packed_[a] = {n_[e], mob[c.i], mob_k, comp_[e], c.i, c.wall ? spare : c.k};
    }
  });
  ic0_ready_ = uses_ic0() && factor_ic0(pairs);
  if (!coupled_ && !ic0_ready_) return solve_cg_jacobi(rtol, 10 * static_cast<long>(m) + 10);
  return pcg(
      r_, rtol, 10 * static_cast<long>(m) + 10,
      [&](const std::vector<double>& p, std::vector<double>& out) { apply(pairs, p, out); },
      [&](const std::vector<double>& r, std::vector<double>& z) { precondition(r, z); }, d_, cg_);
}

long ContactDual::resolve_clipped(const std::vector<ContactPair>& pairs, double rtol) {
  const std::size_t m = act_.size();
  clipped_.assign(m, 0);
  bool any = false;
  for (std::size_t a = 0; a < m; ++a)
    if (lambda_[act_[a]] + d_[a] < 0) clipped_[a] = 1, any = true;
  if (!any) return 0;
  zero_force_.assign(m, 0.0);
  for (std::size_t a = 0; a < m; ++a)
    if (clipped_[a]) zero_force_[a] = -lambda_[act_[a]];
  const std::vector<double> first = d_;  // r_ still holds solve_cg's right-hand side (pcg works on a copy)
  return pcg_fixed(
      r_, clipped_, zero_force_, first, rtol, 10 * static_cast<long>(m) + 10,
      [&](const std::vector<double>& p, std::vector<double>& out) { apply(pairs, p, out); },
      [&](const std::vector<double>& r, std::vector<double>& z) { precondition(r, z); }, d_, cg_);
}

NewtonResult ContactDual::solve(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b,
                                const std::vector<Vec3>& x_start, const WallParticles& walls_start,
                                const WallParticles& walls, const Box& box,
                                double radius, double hertz_k, const std::vector<double>& mob,
                                MobilityCoupling* coupled, double coupled_scale, const NewtonOptions& opt,
                                std::vector<Vec3>& y) {
  const std::size_t np = pairs.size();
  mob_ = &mob;
  coupled_ = coupled;
  coupled_scale_ = coupled_scale;
  const double two_r = 2.0 * radius;
  const MinImageYZ mi(box);
  lambda_.resize(np);
  n_.resize(np);
  comp_.resize(np);
  rhs_.resize(np);
  s_.resize(b.size());
  disp_.resize(b.size());
  const int pair_blocks = detail::block_count(np, k_dual_per_thread);
  if (coupled_) {  // s (C_ii + C_kk - 2 C_ik) of each candidate: the diagonal of s G^T C G (Jacobi)
    crel_.resize(np);
    cik_.resize(np);
    for (std::size_t c = 0; c < np; ++c) {
      const ContactPair& pc = pairs[c];
      cik_[c] = pc.wall ? 0.0 : coupled_->coupling(pc.i, pc.k);
      double v = coupled_->diagonal(pc.i);
      if (!pc.wall) v += coupled_->diagonal(pc.k) - 2.0 * cik_[c];
      crel_[c] = coupled_scale_ * std::max(0.0, v);
    }
  }
  // Warm start: the Hertz forces at x_start, along its normals. The normal
  // of a pair without force is never read (every product skips a zero
  // force, and an inactive pair's is set before it becomes active), so an
  // open pair costs no square root or division here or below: most
  // candidates are open.
  const double two_r2 = two_r * two_r;
  detail::for_blocks(np, pair_blocks, [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t c = lo; c < hi; ++c) {
      const Vec3 r = pair_vector(pairs[c], x_start, walls_start, mi);
      const double r2 = r.squaredNorm();
      if (r2 >= two_r2) {
        lambda_[c] = 0.0;
        continue;
      }
      const double rn = std::sqrt(r2);
      n_[c] = r * (1.0 / rn);
      lambda_[c] = hertz_force(two_r - rn, hertz_k);
    }
  });
  // Every pair with a force is active in the passes below (an active set
  // holds every pair with lambda > 0), so a move by the active set's forces
  // is a move by all of them.
  detail::in_blocks(np, k_dual_per_thread, act_, [&](std::size_t lo, std::size_t hi, std::vector<std::uint32_t>& mine) {
    for (std::size_t c = lo; c < hi; ++c)
      if (lambda_[c] > 0) mine.push_back(static_cast<std::uint32_t>(c));
  });
  index_spheres(pairs);
  detail::copy_on_threads(b, y, k_dual_per_thread);
  move(pairs, lambda_, true, y);
  const double inv_k23 = 1.0 / std::cbrt(hertz_k * hertz_k);  // k^{-2/3}
  // lambda += t d on the active set (projected on lambda >= 0), y moved by
  // the change along the current normals
  auto update = [&](double t, const std::vector<double>& d, std::vector<Vec3>& y_out) {
    const std::size_t m = act_.size();
    dq_.resize(m);
    detail::for_blocks(m, detail::block_count(m, k_dual_per_thread), [&](std::size_t, std::size_t lo, std::size_t hi) {
      for (std::size_t a = lo; a < hi; ++a) {
        const std::uint32_t c = act_[a];
        const double updated = std::max(0.0, lambda_[c] + t * d[a]);
        dq_[a] = updated - lambda_[c];
        lambda_[c] = updated;
      }
    });
    move(pairs, dq_, false, y_out);
  };
  act_part_.resize(static_cast<std::size_t>(pair_blocks));
  std::vector<detail::Largest> worst_of(static_cast<std::size_t>(std::max(pair_blocks, 1)));
  NewtonResult res;
  double prev_worst = 0, theta = 1.0;
  // the largest residual of the last two accepted iterates, and whether the
  // solve has stalled (see resolve_clipped)
  double worst_1 = 0, worst_2 = 0;
  bool stalled = false;
  for (res.iterations = 1; res.iterations <= opt.max_iterations; ++res.iterations) {
    // Residuals at y, normals updated to y; y_next = b + M G(y) lambda. By
    // blocks of pairs, each listing its active pairs, joined in order.
    worst_of.assign(static_cast<std::size_t>(pair_blocks), detail::Largest{});
    detail::for_blocks(np, pair_blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
      // the block's own list and maximum, handed back at the end (as in
      // detail::in_blocks: act_'s header is next to the members read here)
      std::vector<std::uint32_t> mine;
      mine.swap(blk == 0 ? act_ : act_part_[blk]);
      mine.clear();
      detail::Largest w;  // the largest |residual| and its sphere i
      for (std::size_t c = lo; c < hi; ++c) {
        const ContactPair& pc = pairs[c];
        const Vec3 r = pair_vector(pc, y, walls, mi);
        const double r2 = r.squaredNorm();
        if (lambda_[c] <= 0 && r2 >= two_r2) continue;  // open and staying open
        const double rn = std::sqrt(r2), h = two_r - rn;
        n_[c] = r * (1.0 / rn);
        const double h_lambda = std::cbrt(lambda_[c] * lambda_[c]) * inv_k23;  // (lambda/k)^{2/3}
        const double phi = h - h_lambda;  // the Hertz law's residual as an overlap
        rhs_[c] = phi;
        // Compliance slope: of the current force, or for a contact closing
        // from zero force, of the Hertz law at the overlap y gives it.
        comp_[c] = lambda_[c] > 0 ? 2.0 * h_lambda / (3.0 * lambda_[c]) : 1.0 / hertz_local_stiffness(h, hertz_k);
        mine.push_back(static_cast<std::uint32_t>(c));
        w.see(std::abs(phi), pc.i);
      }
      mine.swap(blk == 0 ? act_ : act_part_[blk]);
      worst_of[blk] = w;
    });
    for (int blk = 1; blk < pair_blocks; ++blk)
      act_.insert(act_.end(), act_part_[static_cast<std::size_t>(blk)].begin(),
                  act_part_[static_cast<std::size_t>(blk)].end());
    detail::Largest worst_at;  // over both passes, in order
    for (const detail::Largest& w : worst_of) worst_at.merge(w);
    index_spheres(pairs);
    detail::copy_on_threads(b, y_next_, k_dual_per_thread);
    move(pairs, lambda_, true, y_next_);
    // y was placed with the normals of the last iterate; with the normals
    // just updated, y - y_next = r_y. Newton on (y, lambda) with r_y
    // eliminated: (A + C) dlambda = phi + G^T r_y, and the next y is
    // y_next + M G(y) dlambda. Without the G^T r_y term the normals
    // converge only linearly (30 % more iterations).
    const std::size_t m = act_.size();
    const int act_blocks = detail::block_count(m, k_dual_per_thread);
    worst_of.assign(static_cast<std::size_t>(act_blocks), detail::Largest{});
    detail::for_blocks(m, act_blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
      detail::Largest w;  // stored at the end: the blocks' slots share a cache line
      for (std::size_t a = lo; a < hi; ++a) {
        const std::uint32_t c = act_[a];
        const ContactPair& pc = pairs[c];
        const Vec3 ry = pc.wall ? Vec3(y[pc.i] - y_next_[pc.i])
                                : Vec3((y[pc.i] - y_next_[pc.i]) - (y[pc.k] - y_next_[pc.k]));
        rhs_[c] += n_[c].dot(ry);
        w.see(std::abs(rhs_[c]), pc.i);
      }
      worst_of[blk] = w;
    });
    for (const detail::Largest& w : worst_of) worst_at.merge(w);
    const double worst = worst_at.v;
    if (worst_at.at != detail::Largest::npos) res.worst = static_cast<std::uint32_t>(worst_at.at);
    // Backtracking: an update that more than doubled the largest residual
    // is undone and taken at half its length (down to 1/8; each try counts
    // as an iteration). Without it the coupled solve can cycle: a contact
    // that opens leaves a force the fluid does not see balanced, the fluid
    // response moves a whole neighbourhood by more than the residual it
    // fixed, the contact closes again (seen on the small scene at 2000 1/s,
    // model 3: periods of 2 and 3 iterations until the 20 allowed ran out).
    if (res.iterations > 1 && worst > opt.tol && worst > 2.0 * prev_worst && theta > 0.2) {
      theta *= 0.5;
      detail::copy_on_threads(lambda_prev_, lambda_, k_dual_per_thread);
      detail::copy_on_threads(y_prev_, y, k_dual_per_thread);
      n_.swap(n_prev_);
      act_.swap(act_prev_);
      index_spheres(pairs);  // of the previous active set (the next iteration indexes its own)
      update(theta, d_prev_, y);
      act_.swap(act_prev_);
      n_.swap(n_prev_);
      continue;
    }
    theta = 1.0;
    prev_worst = worst;
    res.last_correction = worst;
    if (!std::isfinite(worst)) return res;
    if (worst <= opt.tol) {
      res.converged = true;
      return res;
    }
    res.linear_iterations += solve_cg(pairs, opt.linear_rtol);
    if (res.iterations >= 4 && worst > 0.5 * worst_2) stalled = true;
    worst_2 = worst_1;
    worst_1 = worst;
    if (stalled) res.linear_iterations += resolve_clipped(pairs, opt.linear_rtol);
    y.swap(y_next_);
    detail::copy_on_threads(lambda_, lambda_prev_, k_dual_per_thread);  // for a backtrack
    detail::copy_on_threads(y, y_prev_, k_dual_per_thread);
    detail::copy_on_threads(n_, n_prev_, k_dual_per_thread);
    act_prev_ = act_;
    d_prev_ = d_;
    update(1.0, d_, y);
  }
  res.iterations = opt.max_iterations;
  return res;
}

}  // namespace mrf
