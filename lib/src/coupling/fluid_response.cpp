#include "mrf/coupling/fluid_response.hpp"

#include <algorithm>
#include <stdexcept>

#include "mrf/fluid/kernel.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "coupling/dem_runs.hpp"

namespace mrf {

double FluidResponse::jacobian_bound(double h) { return KernelW(h)(k_jacobian_q * h); }

void FluidResponse::set(std::size_t n_dem, const std::vector<CouplingPair>& pairs, const std::vector<double>& s,
                        const std::vector<double>& rho, double mass, double w_jacobian_min) {
  // Per DEM particle its SPH neighbours in the order of the pairs (pairs
  // come sorted by DEM index, then SPH index, so the periodic images of one
  // neighbour are adjacent: their weights add). Rebuilt every step into the
  // same buffers.
  const std::size_t na = rho.size();
  mass_ = mass;
  // C's entries per DEM particle
  std::vector<std::uint32_t>& col = exact_.by_dem.col;
  std::vector<std::uint32_t>& start = exact_.by_dem.start;
  std::vector<double>& weight = exact_.by_dem.w;
  start.assign(n_dem + 1, 0);
  diag_.assign(n_dem, 0.0);
  // Blocks of DEM rows on threads, each filling its own entries (row ends
  // counted within the block, shifted when the blocks are joined in order):
  // the serial entries whatever the threads.
  const int blocks = detail::block_count(pairs.size(), detail::k_exchange_pairs_per_thread);
  part_a_.resize(static_cast<std::size_t>(blocks));
  part_scatter_.resize(static_cast<std::size_t>(blocks));
  std::vector<char> unsorted(static_cast<std::size_t>(blocks), 0);
  detail::for_blocks(n_dem, blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
    // the block's own lists, handed back at the end: a push_back into col
    // would write its header next to the members the other threads read
    // (false sharing; docs/performance.md, session 29)
    std::vector<std::uint32_t> a;
    std::vector<double> sc_of;
    a.swap(blk == 0 ? col : part_a_[blk]);
    sc_of.swap(blk == 0 ? weight : part_scatter_[blk]);
    a.clear();
    sc_of.clear();
    bool unordered = false;
    std::size_t next = static_cast<std::size_t>(
        std::lower_bound(pairs.begin(), pairs.end(), lo, [](const CouplingPair& q, std::size_t i) { return q.i < i; }) -
        pairs.begin());
    for (std::size_t i = lo; i < hi; ++i) {
      const std::size_t row = a.size();
      for (; next < pairs.size() && pairs[next].i == i; ++next) {
        const CouplingPair& q = pairs[next];
        const double sc = q.w / (rho[q.a] * s[i]);
        if (a.size() > row && a.back() == q.a) {
          sc_of.back() += sc;
        } else {
          if (a.size() > row && a.back() > q.a) unordered = true;
          a.push_back(q.a);
          sc_of.push_back(sc);
        }
      }
      start[i + 1] = static_cast<std::uint32_t>(a.size());  // checked below, with the joined size
      for (std::size_t e = row; e < a.size(); ++e) diag_[i] += mass * sc_of[e] * sc_of[e];
    }
    a.swap(blk == 0 ? col : part_a_[blk]);
    sc_of.swap(blk == 0 ? weight : part_scatter_[blk]);
    unsorted[blk] = unordered ? 1 : 0;
  });
  if (std::find(unsorted.begin(), unsorted.end(), 1) != unsorted.end())
    throw std::logic_error("FluidResponse::set: pairs not sorted by (i, a)");
  std::size_t total = col.size();
  for (int blk = 1; blk < blocks; ++blk) total += part_a_[static_cast<std::size_t>(blk)].size();
  checked_index(total, "fluid response");
  for (int blk = 1; blk < blocks; ++blk) {
    const auto b = static_cast<std::size_t>(blk);
    const std::size_t offset = col.size();
    col.insert(col.end(), part_a_[b].begin(), part_a_[b].end());
    weight.insert(weight.end(), part_scatter_[b].begin(), part_scatter_[b].end());
    for (std::size_t i = detail::block_bound(n_dem, b, static_cast<std::size_t>(blocks));
         i < detail::block_bound(n_dem, b + 1, static_cast<std::size_t>(blocks)); ++i)
      start[i + 1] = static_cast<std::uint32_t>(start[i + 1] + offset);
  }
  // C_J: the entries of C whose kernel value reaches the bound, in the same
  // order (one pass: a small share of set(), itself a small share of a step).
  // It reads col as SPH indices: before index_by_sph(exact_) turns them into
  // offsets.
  if (w_jacobian_min > 0) {
    if (!jacobian_) jacobian_.emplace();
    Csr& j = jacobian_->by_dem;
    j.start.assign(n_dem + 1, 0);
    j.col.clear();
    j.w.clear();
    for (std::size_t i = 0; i < n_dem; ++i) {
      for (std::uint32_t e = start[i]; e < start[i + 1]; ++e)
        if (weight[e] * rho[col[e]] * s[i] >= w_jacobian_min) {  // the entry's W, over its images
          j.col.push_back(col[e]);
          j.w.push_back(weight[e]);
        }
      j.start[i + 1] = static_cast<std::uint32_t>(j.col.size());
    }
    index_by_sph(*jacobian_, na, blocks);
  } else {
    jacobian_.reset();
  }
  index_by_sph(exact_, na, blocks);
  dense_.assign(4 * na, 0.0);
}

void FluidResponse::index_by_sph(Entries& e, std::size_t na, int blocks) {
  // The same entries by SPH particle (CSR over a), so that the scatter is a
  // gather too: both passes run on threads without write conflicts, each
  // sum in a fixed order. Built by the same blocks of DEM rows as set():
  // each block counts its entries per SPH particle, the counts become each
  // block's first free slot per SPH particle (block 0's entries first), and
  // each block fills its own slots: every SPH particle's entries in
  // ascending DEM order, as one pass over the rows would put them.
  const Csr& d = e.by_dem;
  Csr& r = e.by_sph;
  const std::size_t n_dem = d.start.size() - 1;
  fill_.resize(static_cast<std::size_t>(blocks));
  detail::for_blocks(n_dem, blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
    std::vector<std::uint32_t>& count = fill_[blk];
    count.assign(na, 0);
    for (std::uint32_t k = d.start[lo]; k < d.start[hi]; ++k) ++count[d.col[k]];
  });
  r.start.assign(na + 1, 0);
  for (std::size_t b = 0; b < na; ++b) {
    std::uint32_t slot = r.start[b];
    for (std::vector<std::uint32_t>& count : fill_) {
      const std::uint32_t n = count[b];
      count[b] = slot;
      slot += n;
    }
    r.start[b + 1] = slot;
  }
  r.col.resize(d.col.size());
  r.w.resize(d.col.size());
  detail::for_blocks(n_dem, blocks, [&](std::size_t blk, std::size_t lo, std::size_t hi) {
    std::vector<std::uint32_t>& next = fill_[blk];
    for (std::size_t i = lo; i < hi; ++i)
      for (std::uint32_t k = d.start[i]; k < d.start[i + 1]; ++k) {
        const std::uint32_t slot = next[d.col[k]]++;
        r.col[slot] = static_cast<std::uint32_t>(i);
        r.w[slot] = d.w[k];
      }
  });
  // From here on both index lists hold offsets into xyz padded to four
  // doubles (4 x index): the gathers address x[4 col] without a shift.
  checked_index(4 * std::max(na, n_dem), "fluid response offset");
  for (std::uint32_t& b : e.by_dem.col) b *= 4;
  for (std::uint32_t& j : r.col) j *= 4;
}

double FluidResponse::coupling(std::size_t i, std::size_t k) const {
  const std::vector<std::uint32_t>& col = exact_.by_dem.col;
  const std::vector<std::uint32_t>& start = exact_.by_dem.start;
  const std::vector<double>& weight = exact_.by_dem.w;
  // i's gather weights spread over its SPH neighbours, read back by k's
  for (std::uint32_t p = start[i]; p < start[i + 1]; ++p) dense_[col[p]] = weight[p];
  double c = 0;
  for (std::uint32_t q = start[k]; q < start[k + 1]; ++q) c += dense_[col[q]] * weight[q];
  c *= mass_;
  for (std::uint32_t p = start[i]; p < start[i + 1]; ++p) dense_[col[p]] = 0.0;
  return c;
}

namespace {
// The two gathers of FluidResponse::add on xyz padded to four doubles, so
// that one entry is one offset (4 x index, stored ready, read with a 64-bit
// running position), one weight and one four-wide load, multiply and add.
// Four partial sums per row (entries e, e+1, e+2, e+3 mod 4), added pairwise
// at the end: one sum alone is a chain of dependent adds, one entry per add
// latency. The order is fixed by the pairs alone, so the result does not
// depend on the thread count. Cloned for AVX2 and the baseline, chosen when
// the program loads; neither clone has FMA, so a product and its add stay
// two roundings on both (GCC would fuse them where FMA is enabled: its C++
// default is -ffp-contract=fast). What each choice measured, and the
// variants that were slower (float weights, an AVX-512 clone, Highway):
// docs/performance.md, "The fluid response's gathers".
__attribute__((target_clones("avx2", "default"))) void gather4(std::size_t rows, const std::uint32_t* row_of,
                                                                 const std::uint32_t* start, const std::uint32_t* col,
                                                                 const double* w, const double* in, double* out,
                                                                 bool threads) {
#pragma omp parallel for schedule(static) if (threads)
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t i = row_of ? row_of[r] : r;
    double s0[4] = {0, 0, 0, 0}, s1[4] = {0, 0, 0, 0}, s2[4] = {0, 0, 0, 0}, s3[4] = {0, 0, 0, 0};
    const std::uint32_t* c = col + start[i];
    const double* wt = w + start[i];
    const std::size_t len = start[i + 1] - start[i];
    std::size_t e = 0;
    for (; e + 4 <= len; e += 4) {
      const double* x0 = in + c[e];
      const double* x1 = in + c[e + 1];
      const double* x2 = in + c[e + 2];
      const double* x3 = in + c[e + 3];
      for (int k = 0; k < 4; ++k) {
        s0[k] += wt[e] * x0[k];
        s1[k] += wt[e + 1] * x1[k];
        s2[k] += wt[e + 2] * x2[k];
        s3[k] += wt[e + 3] * x3[k];
      }
    }
    for (; e < len; ++e) {
      const double* x = in + c[e];
      for (int k = 0; k < 4; ++k) s0[k] += wt[e] * x[k];
    }
    for (int k = 0; k < 4; ++k) out[4 * i + k] = (s0[k] + s1[k]) + (s2[k] + s3[k]);
  }
}
}  // namespace

void FluidResponse::add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                        const std::vector<std::uint32_t>* rows) {
  product(exact_, f, scale, y, rows);
}

void FluidResponse::add_jacobian(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                                 const std::vector<std::uint32_t>* rows) {
  product(jacobian_ ? *jacobian_ : exact_, f, scale, y, rows);
}

void FluidResponse::product(const Entries& en, const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                            const std::vector<std::uint32_t>* rows) {
  // z_a = sum_j W_aj f_j / (rho_a s_j), then y_i += scale sum_a m W_ia z_a /
  // (rho_a s_i): two gathers (by SPH particle, by DEM particle), the cost of
  // a coupled contact solve (one per CG iteration). OpenMP over the outer
  // index, so each sum keeps its order.
  const std::size_t n = f.size(), na = en.by_sph.start.size() - 1;
  f4_.resize(4 * n);
  y4_.resize(4 * n);
  z4_.resize(4 * na);
  const bool threads = en.by_dem.col.size() > k_entries_per_thread;
  // the packing and unpacking on threads too: serial, they were a third of
  // the main thread's own share of a product on two threads
  const std::size_t per_thread = threads ? 1 : n + 1;
  detail::for_each_index(n, per_thread, [&](std::size_t j) {
    f4_[4 * j] = f[j].x(), f4_[4 * j + 1] = f[j].y(), f4_[4 * j + 2] = f[j].z(), f4_[4 * j + 3] = 0.0;
  });
  gather4(na, nullptr, en.by_sph.start.data(), en.by_sph.col.data(), en.by_sph.w.data(), f4_.data(), z4_.data(),
          threads);
  const std::size_t m = rows ? rows->size() : n;
  const std::uint32_t* row_of = rows ? rows->data() : nullptr;
  gather4(m, row_of, en.by_dem.start.data(), en.by_dem.col.data(), en.by_dem.w.data(), z4_.data(), y4_.data(),
          threads);
  const double gscale = scale * mass_;
  detail::for_each_index(m, per_thread, [&](std::size_t r) {
    const std::size_t i = row_of ? row_of[r] : r;
    y[i].x() += gscale * y4_[4 * i];
    y[i].y() += gscale * y4_[4 * i + 1];
    y[i].z() += gscale * y4_[4 * i + 2];
  });
}

}  // namespace mrf
