#include "mrf/coupling/fluid_response.hpp"

#include <algorithm>
#include <numeric>

namespace mrf {

void FluidResponse::set(std::size_t n_dem, const std::vector<CouplingPair>& pairs, const std::vector<double>& s,
                        const std::vector<double>& rho, double mass) {
  // Per DEM particle its SPH neighbours sorted by index, the periodic images
  // of one neighbour merged (their weights add): C_ik is then a merge of two
  // short sorted lists.
  start_.assign(n_dem + 1, 0);
  for (const CouplingPair& q : pairs) ++start_[q.i + 1];
  for (std::size_t i = 0; i < n_dem; ++i) start_[i + 1] += start_[i];
  order_.resize(pairs.size());
  std::iota(order_.begin(), order_.end(), 0u);
  a_.clear();
  scatter_.clear();
  gather_.clear();
  std::vector<std::uint32_t> merged(n_dem + 1, 0);
  for (std::size_t i = 0; i < n_dem; ++i) {
    const auto b = order_.begin() + start_[i], e = order_.begin() + start_[i + 1];
    std::sort(b, e, [&](std::uint32_t x, std::uint32_t y) { return pairs[x].a < pairs[y].a; });
    for (auto it = b; it != e; ++it) {
      const CouplingPair& q = pairs[*it];
      const double sc = q.w / (rho[q.a] * s[i]);
      if (!a_.empty() && a_.size() > merged[i] && a_.back() == q.a) {
        scatter_.back() += sc;
        gather_.back() += mass * sc;
      } else {
        a_.push_back(q.a);
        scatter_.push_back(sc);
        gather_.push_back(mass * sc);
      }
    }
    merged[i + 1] = static_cast<std::uint32_t>(a_.size());
  }
  start_ = std::move(merged);
  // The same entries by SPH particle (CSR over a), so that the scatter is a
  // gather too: both passes run on threads without write conflicts, each
  // sum in a fixed order.
  const std::size_t na = rho.size();
  rstart_.assign(na + 1, 0);
  for (std::uint32_t b : a_) ++rstart_[b + 1];
  for (std::size_t b = 0; b < na; ++b) rstart_[b + 1] += rstart_[b];
  rdem_.resize(a_.size());
  rscatter_.resize(a_.size());
  std::vector<std::uint32_t> fill(rstart_.begin(), rstart_.end() - 1);
  for (std::size_t i = 0; i < n_dem; ++i)
    for (std::uint32_t e = start_[i]; e < start_[i + 1]; ++e) {
      const std::uint32_t slot = fill[a_[e]]++;
      rdem_[slot] = static_cast<std::uint32_t>(i);
      rscatter_[slot] = scatter_[e];
    }
  diag_.assign(n_dem, 0.0);
  for (std::size_t i = 0; i < n_dem; ++i)
    for (std::uint32_t e = start_[i]; e < start_[i + 1]; ++e) diag_[i] += gather_[e] * scatter_[e];
  z_.assign(3 * rho.size(), 0.0);
}

double FluidResponse::coupling(std::size_t i, std::size_t k) const {
  double c = 0;
  std::uint32_t p = start_[i], q = start_[k];
  while (p < start_[i + 1] && q < start_[k + 1]) {
    if (a_[p] < a_[q]) {
      ++p;
    } else if (a_[q] < a_[p]) {
      ++q;
    } else {
      c += gather_[p] * scatter_[q];
      ++p, ++q;
    }
  }
  return c;
}

void FluidResponse::add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                        const std::vector<std::uint32_t>* rows) {
  // z_a = sum_j W_aj f_j / (rho_a s_j), then y_i += scale sum_a m W_ia z_a /
  // (rho_a s_i): two gathers (by SPH particle, by DEM particle), the cost of
  // a coupled contact solve (one per CG iteration). Raw arrays, z by
  // component; OpenMP over the outer index, so each sum keeps its order.
  const std::size_t n = f.size(), na = rstart_.size() - 1;
  double* zx = z_.data();
  double* zy = zx + na;
  double* zz = zy + na;
  const std::uint32_t* a = a_.data();
  const std::uint32_t* rj = rdem_.data();
  const double* rs = rscatter_.data();
  const double* ga = gather_.data();
  const Vec3* fv = f.data();
  const bool threads = a_.size() > k_entries_per_thread;
#pragma omp parallel for schedule(static) if (threads)
  for (std::size_t b = 0; b < na; ++b) {
    double sx = 0, sy = 0, sz = 0;
    for (std::uint32_t e = rstart_[b], end = rstart_[b + 1]; e < end; ++e) {
      const Vec3& fj = fv[rj[e]];
      sx += rs[e] * fj.x();
      sy += rs[e] * fj.y();
      sz += rs[e] * fj.z();
    }
    zx[b] = sx, zy[b] = sy, zz[b] = sz;
  }
  const std::size_t m = rows ? rows->size() : n;
#pragma omp parallel for schedule(static) if (threads)
  for (std::size_t r = 0; r < m; ++r) {
    const std::size_t i = rows ? (*rows)[r] : r;
    double sx = 0, sy = 0, sz = 0;
    for (std::uint32_t e = start_[i], end = start_[i + 1]; e < end; ++e) {
      const std::uint32_t b = a[e];
      sx += ga[e] * zx[b];
      sy += ga[e] * zy[b];
      sz += ga[e] * zz[b];
    }
    y[i].x() += scale * sx;
    y[i].y() += scale * sy;
    y[i].z() += scale * sz;
  }
}

}  // namespace mrf
