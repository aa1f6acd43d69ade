#include "mrf/coupling/fluid_response.hpp"

#include <algorithm>
#include <stdexcept>

#include "mrf/neighbors/cell_list.hpp"

namespace mrf {

void FluidResponse::set(std::size_t n_dem, const std::vector<CouplingPair>& pairs, const std::vector<double>& s,
                        const std::vector<double>& rho, double mass) {
  // Per DEM particle its SPH neighbours in the order of the pairs (pairs
  // come sorted by DEM index, then SPH index, so the periodic images of one
  // neighbour are adjacent: their weights add).
  const std::size_t na = rho.size();
  mass_ = mass;
  a_.clear();
  scatter_.clear();
  std::vector<std::uint32_t> merged(n_dem + 1, 0);
  std::size_t next = 0;
  for (std::size_t i = 0; i < n_dem; ++i) {
    const std::size_t row = a_.size();
    for (; next < pairs.size() && pairs[next].i == i; ++next) {
      const CouplingPair& q = pairs[next];
      const double sc = q.w / (rho[q.a] * s[i]);
      if (a_.size() > row && a_.back() == q.a) {
        scatter_.back() += sc;
      } else {
        if (a_.size() > row && a_.back() > q.a) throw std::logic_error("FluidResponse::set: pairs not sorted by (i, a)");
        a_.push_back(q.a);
        scatter_.push_back(sc);
      }
    }
    merged[i + 1] = checked_index(a_.size(), "fluid response");
  }
  start_ = std::move(merged);
  // The same entries by SPH particle (CSR over a), so that the scatter is a
  // gather too: both passes run on threads without write conflicts, each
  // sum in a fixed order.
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
    for (std::uint32_t e = start_[i]; e < start_[i + 1]; ++e) diag_[i] += mass * scatter_[e] * scatter_[e];
  z_.assign(3 * na, 0.0);
  dense_.assign(na, 0.0);
}

double FluidResponse::coupling(std::size_t i, std::size_t k) const {
  // i's gather weights spread over its SPH neighbours, read back by k's
  for (std::uint32_t p = start_[i]; p < start_[i + 1]; ++p) dense_[a_[p]] = scatter_[p];
  double c = 0;
  for (std::uint32_t q = start_[k]; q < start_[k + 1]; ++q) c += dense_[a_[q]] * scatter_[q];
  c *= mass_;
  for (std::uint32_t p = start_[i]; p < start_[i + 1]; ++p) dense_[a_[p]] = 0.0;
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
  const double* ga = scatter_.data();
  const double gscale = scale * mass_;
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
    y[i].x() += gscale * sx;
    y[i].y() += gscale * sy;
    y[i].z() += gscale * sz;
  }
}

}  // namespace mrf
