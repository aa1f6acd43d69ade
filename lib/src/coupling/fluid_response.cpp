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

void FluidResponse::add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y) {
  // Raw arrays, z by component: the two passes are the cost of a coupled
  // contact solve (one per CG iteration).
  const std::size_t n = f.size(), nz = z_.size() / 3;
  std::fill(z_.begin(), z_.end(), 0.0);
  double* zx = z_.data();
  double* zy = zx + nz;
  double* zz = zy + nz;
  const std::uint32_t* a = a_.data();
  const double* sc = scatter_.data();
  const double* ga = gather_.data();
  bool any = false;
  for (std::size_t j = 0; j < n; ++j) {
    const double fx = f[j].x(), fy = f[j].y(), fz = f[j].z();
    if (fx == 0 && fy == 0 && fz == 0) continue;
    any = true;
    for (std::uint32_t e = start_[j], end = start_[j + 1]; e < end; ++e) {
      const std::uint32_t b = a[e];
      zx[b] += sc[e] * fx;
      zy[b] += sc[e] * fy;
      zz[b] += sc[e] * fz;
    }
  }
  if (!any) return;
  for (std::size_t i = 0; i < n; ++i) {
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
