// The contact solve's CG without a coupled mobility (model 1, Jacobi
// preconditioner; integrate/contact_dual.hpp), in one parallel region, and
// the parts of its product that apply() shares.
//
// Each thread keeps one block of spheres and one block of contacts for the
// whole solve: with the spheres numbered in slabs (scene/shear_cell.hpp)
// the blocks are slabs of the cell, so a thread's vectors stay in its own
// cache and only a slab face's contacts cross. Four barriers an iteration,
// where a serial CG between threaded products moved every vector from core
// to core twice an iteration (docs/performance.md, session 28).
//
// The dot products are summed in fixed chunks of contacts and the chunks'
// sums added in order, whatever the number of threads, and the pass by
// spheres adds each sphere's terms in the order of the pass by contacts
// (ContactDual::index_spheres), so the iterates are the same bit for bit on
// any number of threads.
#include <omp.h>

#include <algorithm>

#include "mrf/integrate/contact_dual.hpp"
#include "parallel_blocks.hpp"

namespace mrf {

namespace {
constexpr std::size_t k_dot_chunk = 256;  // contacts per partial sum of a dot product
}

// Without a coupled mobility, M G p from the packed pairs: by a pass over
// the contacts (one thread), or for the active spheres lo..hi by their
// entries (index_spheres), the same sums in the same order.
void ContactDual::packed_scatter(const double* p) {
  for (auto i : act_particles_) pdisp_[i].setZero();
  for (std::size_t a = 0; a < packed_.size(); ++a) {
    const Packed& e = packed_[a];
    const Vec3 g = p[a] * e.n;
    pdisp_[e.i] += e.mob_i * g;
    pdisp_[e.k] -= e.mob_k * g;  // a wall pair: the spare row, 0 * g
  }
}

void ContactDual::packed_gather(const double* p, std::size_t lo, std::size_t hi) {
  const std::vector<double>& mob = *mob_;
  for (std::size_t t = lo; t < hi; ++t) {
    const std::uint32_t i = act_particles_[t];
    const double mi = mob[i];
    Vec3 d = Vec3::Zero();
    for (std::uint32_t e = row_start_[i]; e < row_start_[i + 1]; ++e) d += mi * (p[row_entry_[e].a] * row_entry_[e].sn);
    pdisp_[i] = d;
  }
}

// out = n . (M G p at i - at k) + compliance p for the contacts lo..hi
void ContactDual::packed_product(const double* p, double* out, std::size_t lo, std::size_t hi) const {
  for (std::size_t a = lo; a < hi; ++a) {
    const Packed& e = packed_[a];
    out[a] = e.n.dot(pdisp_[e.i] - pdisp_[e.k]) + e.comp * p[a];  // a wall pair's k: the spare row, 0
  }
}

long ContactDual::solve_cg_jacobi(double rtol, long max_it) {
  const std::size_t m = act_.size(), ns = act_particles_.size();
  const std::size_t chunks = (m + k_dot_chunk - 1) / k_dot_chunk;
  PcgScratch<double>& s = cg_;
  d_.assign(m, 0.0);
  s.r = r_;
  s.z.resize(m);
  s.p.resize(m);
  s.q.resize(m);
  dot_part_.assign(3 * chunks, 0.0);
  long iterations = 0;
  // more than one thread only where index_spheres built the sphere entries
#pragma omp parallel num_threads(sphere_blocks_) if (sphere_blocks_ > 1)
  {
    // the team OpenMP gave (it may be smaller than asked): every share below
    const auto t = static_cast<std::size_t>(omp_get_thread_num()),
               nb = static_cast<std::size_t>(omp_get_num_threads());
    const std::size_t k0 = detail::block_bound(chunks, t, nb), k1 = detail::block_bound(chunks, t + 1, nb);
    const std::size_t s0 = detail::block_bound(ns, t, nb), s1 = detail::block_bound(ns, t + 1, nb);
    const std::size_t c0 = std::min(m, k0 * k_dot_chunk), c1 = std::min(m, k1 * k_dot_chunk);
    // raw pointers: the region's loops then need not reload the vectors' data
    double *const x = d_.data(), *const r = s.r.data(), *const z = s.z.data(), *const p = s.p.data(),
                  *const q = s.q.data(), *const part = dot_part_.data();
    const double* const diag = diag_.data();
    // this thread's chunks' partial sums of term(a) into slot `slot`
    const auto partial = [&](std::size_t slot, auto term) {
      for (std::size_t k = k0; k < k1; ++k) {
        double sum = 0;
        for (std::size_t a = k * k_dot_chunk, end = std::min(m, a + k_dot_chunk); a < end; ++a) sum += term(a);
        part[slot * chunks + k] = sum;
      }
    };
    const auto total = [&](std::size_t slot) {
      double sum = 0;
      for (std::size_t k = 0; k < chunks; ++k) sum += part[slot * chunks + k];
      return sum;
    };
    for (std::size_t a = c0; a < c1; ++a) p[a] = z[a] = r[a] / diag[a];
    partial(0, [&](std::size_t a) { return r[a] * z[a]; });
    partial(1, [&](std::size_t a) { return r[a] * r[a]; });
#pragma omp barrier
    double rz = total(0), rr = total(1);
    const double stop2 = rtol * rtol * rr;  // r = b here
    long it = 0;
    while (rr > stop2 && it < max_it) {
      if (nb == 1) {
        packed_scatter(p);
      } else {
        packed_gather(p, s0, s1);
#pragma omp barrier
      }
      packed_product(p, q, c0, c1);
      partial(2, [&](std::size_t a) { return p[a] * q[a]; });
#pragma omp barrier
      const double alpha = rz / total(2);
      for (std::size_t a = c0; a < c1; ++a) {
        x[a] += alpha * p[a];
        r[a] -= alpha * q[a];
        z[a] = r[a] / diag[a];
      }
      partial(0, [&](std::size_t a) { return r[a] * z[a]; });
      partial(1, [&](std::size_t a) { return r[a] * r[a]; });
#pragma omp barrier
      const double rz_new = total(0);
      rr = total(1);
      const double beta = rz_new / rz;
      rz = rz_new;
      for (std::size_t a = c0; a < c1; ++a) p[a] = z[a] + beta * p[a];
      ++it;
#pragma omp barrier
    }
    if (t == 0) iterations = it;
  }
  return iterations;
}

}  // namespace mrf
