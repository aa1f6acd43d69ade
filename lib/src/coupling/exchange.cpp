// Unresolved SPH-DEM coupling kernels, REFERENCE.md §6. See exchange.hpp.
#include "mrf/coupling/exchange.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "mrf/error.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "parallel_blocks.hpp"
#include "coupling/dem_runs.hpp"
#include "coupling/pairs_simd.hpp"

namespace mrf {

namespace {
// DEM particles per thread below which the pair search stays serial
constexpr std::size_t k_coupling_rows_per_thread = 1000;
// candidates per thread below which their evaluation stays serial
constexpr std::size_t k_coupling_candidates_per_thread = 50000;

}  // namespace

void coupling_candidates(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x, const Box& box,
                         double reach, std::vector<IndexPair>& out) {
  if (!(reach > 0.0)) throw std::invalid_argument("coupling_candidates: reach must be > 0");
  const double rc2 = reach * reach;
  double x_lo = 0.0, x_hi = 0.0;
  for (const Vec3& p : sph_x) {
    x_lo = std::min(x_lo, p.x());
    x_hi = std::max(x_hi, p.x());
  }
  for (const Vec3& p : dem_x) {
    x_lo = std::min(x_lo, p.x());
    x_hi = std::max(x_hi, p.x());
  }
  CellGrid grid(box, x_lo - reach, x_hi + reach, reach);
  grid.bin(sph_x);
  const MinImageYZ mi(box);
  // DEM particles in blocks (in_blocks): the candidates come in the same
  // order whatever the number of threads.
  detail::in_blocks(dem_x.size(), k_coupling_rows_per_thread, out,
            [&](std::size_t lo, std::size_t hi, std::vector<IndexPair>& mine) {
              for (std::size_t ii = lo; ii < hi; ++ii) {
                const auto i = static_cast<std::uint32_t>(ii);
                const Vec3 xi = dem_x[i];
                const std::size_t row = mine.size();
                grid.for_each_candidate(xi, [&](std::uint32_t a) {
                  const Vec3& xa = sph_x[a];
                  const double dx = xi.x() - xa.x();
                  const double dy = mi.wrap_y(xi.y() - xa.y()), dz = mi.wrap_z(xi.z() - xa.z());
                  if (dx * dx + dy * dy + dz * dz < rc2) mine.emplace_back(i, a);
                });
                std::sort(mine.begin() + static_cast<std::ptrdiff_t>(row), mine.end());
              }
            });
}

void coupling_pairs_of(const std::vector<IndexPair>& candidates, const std::vector<Vec3>& dem_x,
                       const std::vector<Vec3>& sph_x, const Box& box, double h, std::vector<CouplingPair>& out,
                       std::vector<Vec3>* grad) {
  if (!(h > 0.0)) throw std::invalid_argument("coupling_pairs: smoothing length h must be > 0");
  const double rc = k_kernel_support * h, rc2 = rc * rc;
  // Every periodic image closer than rc is its own entry: along y (z) a
  // second image can interact only when ly (lz) < 2 rc = 4h.
  const bool ky = box.ly < 2.0 * rc, kz = box.lz < 2.0 * rc;
  if ((ky && box.ly < rc) || (kz && box.lz < rc))
    throw std::invalid_argument("coupling_pairs: periodic lengths below the kernel support 2h (ly " +
                                std::to_string(box.ly) + " m, lz " + std::to_string(box.lz) + " m, 2h " +
                                std::to_string(rc) + " m): a pair would interact through more than two images");
  const MinImageYZ mi(box);
  const bool with_grad = grad != nullptr;
  std::vector<Vec3> unused;
  // candidates in blocks (in_blocks2), the pairs in candidate order: the
  // range test on the vector units (pairs_simd.hpp), then the kernel over all
  // of a block's r^2 at once (kernel_rows), and (dW/dr)/r scales the
  // separation: the same numbers as KernelW per pair.
  detail::in_blocks2(candidates.size(), k_coupling_candidates_per_thread, out, with_grad ? *grad : unused,
                     [&](std::size_t lo, std::size_t hi, std::vector<CouplingPair>& mine, std::vector<Vec3>& mine_dw) {
                       thread_local detail::InRange in;
                       thread_local std::vector<double> ws, fs;
                       const detail::InRangeQuery q{candidates.data(), reinterpret_cast<const double*>(dem_x.data()),
                                                    reinterpret_cast<const double*>(sph_x.data()), box.ly, box.lz,
                                                    mi.inv_ly, mi.inv_lz, rc2, ky, kz, with_grad};
                       detail::in_range_candidates(q, lo, hi, in);
                       const std::size_t m = in.n;
                       if (ws.size() < m) ws.resize(m), fs.resize(m);
                       kernel_rows(KernelW(h), in.r2.data(), m, ws.data(), fs.data());
                       mine.reserve(m);
                       for (std::size_t p = 0; p < m; ++p)
                         mine.push_back({static_cast<std::uint32_t>(in.ends[p]),
                                         static_cast<std::uint32_t>(in.ends[p] >> 32), ws[p]});
                       if (!with_grad) return;
                       mine_dw.reserve(m);
                       for (std::size_t p = 0; p < m; ++p) mine_dw.push_back(Vec3(in.sx[p], in.sy[p], in.sz[p]) * fs[p]);
                     });
}

void coupling_pairs(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x, const Box& box, double h,
                    std::vector<CouplingPair>& out, std::vector<Vec3>* grad) {
  if (!(h > 0.0)) throw std::invalid_argument("coupling_pairs: smoothing length h must be > 0");  // named as h, not as the reach
  std::vector<IndexPair> candidates;
  coupling_candidates(dem_x, sph_x, box, k_kernel_support * h, candidates);
  coupling_pairs_of(candidates, dem_x, sph_x, box, h, out, grad);
}

bool coupling_cache_stale(const CouplingPairCache& cache, const std::vector<Vec3>& dem_x,
                          const std::vector<Vec3>& sph_x, const Box& box, double h) {
  if (cache.builds == 0 || cache.dem_ref.size() != dem_x.size() || cache.sph_ref.size() != sph_x.size()) return true;
  const double reach = k_kernel_support * h + cache.skin;
  const double dn = max_nonaffine_displacement(dem_x, cache.dem_ref, box, cache.strain);
  const double sn = max_nonaffine_displacement(sph_x, cache.sph_ref, box, cache.strain);
  // the displacements are minimum-image differences: keep them far below
  // half the box
  const double quarter = 0.25 * std::min(box.ly, box.lz);
  return skin_spent(dn + sn, cache.strain, reach, cache.skin) || max_displacement(dem_x, cache.dem_ref, box) > quarter ||
         max_displacement(sph_x, cache.sph_ref, box) > quarter;
}

void rebuild_coupling_cache(CouplingPairCache& cache, const std::vector<Vec3>& dem_x,
                            const std::vector<Vec3>& sph_x, const Box& box, double h) {
  coupling_candidates(dem_x, sph_x, box, k_kernel_support * h + cache.skin, cache.candidates);
  cache.dem_ref = dem_x;
  cache.sph_ref = sph_x;
  cache.strain = 0;
  ++cache.builds;
}

std::vector<CouplingPair> coupling_pairs(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x,
                                         const Box& box, double h) {
  std::vector<CouplingPair> out;
  coupling_pairs(dem_x, sph_x, box, h, out);
  return out;
}

using detail::by_dem_runs;

PorosityField porosity_at_fluid(std::size_t n_sph, double particle_volume, const std::vector<CouplingPair>& pairs,
                                double floor) {
  std::vector<double> solid(n_sph, 0.0);
  for (const CouplingPair& p : pairs) solid[p.a] += particle_volume * p.w;
  PorosityField out;
  out.eps.resize(n_sph);
  for (std::size_t a = 0; a < n_sph; ++a) {
    const double e = 1.0 - solid[a];
    if (e < floor) ++out.clamped;
    out.eps[a] = std::max(e, floor);
  }
  return out;
}

ShepardField shepard_interpolate(std::size_t n_dem, const std::vector<CouplingPair>& pairs, double mass,
                                 const std::vector<double>& rho, const std::vector<Vec3>& v,
                                 const std::vector<double>& eps) {
  ShepardField out;
  out.s.assign(n_dem, 0.0);
  out.u.assign(n_dem, Vec3::Zero());
  out.eps.assign(n_dem, 0.0);
  by_dem_runs(pairs, [&](std::uint32_t i, std::size_t first, std::size_t last) {
    double si = out.s[i], ei = out.eps[i];
    Vec3 ui = out.u[i];
    for (std::size_t q = first; q < last; ++q) {
      const CouplingPair& p = pairs[q];
      const double wv = mass / rho[p.a] * p.w;
      si += wv;
      ui += wv * v[p.a];
      ei += wv * eps[p.a];
    }
    out.s[i] = si, out.u[i] = ui, out.eps[i] = ei;
  });
  for (std::size_t i = 0; i < n_dem; ++i) {
    if (!(out.s[i] > 0.0))
      throw NumericalError("shepard_interpolate: DEM particle " + std::to_string(i) +
                           " has no SPH neighbour within 2h (Shepard sum s_i = " + std::to_string(out.s[i]) + ")");
    out.u[i] /= out.s[i];
    out.eps[i] /= out.s[i];
  }
  return out;
}

std::vector<Vec3> shepard_rate(const std::vector<CouplingPair>& pairs, const std::vector<Vec3>& dw, double mass,
                               const std::vector<double>& rho, const std::vector<Vec3>& v, const ShepardField& at,
                               const std::vector<Vec3>& c) {
  if (dw.size() != pairs.size())
    throw std::logic_error("shepard_rate: " + std::to_string(dw.size()) + " kernel gradients for " +
                           std::to_string(pairs.size()) + " pairs");
  std::vector<Vec3> out(at.u.size(), Vec3::Zero());
  by_dem_runs(pairs, [&](std::uint32_t i, std::size_t first, std::size_t last) {
    Vec3 oi = out[i];
    for (std::size_t q = first; q < last; ++q) {
      const CouplingPair& p = pairs[q];
      oi += (mass / rho[p.a] * dw[q].dot(c[i] - v[p.a])) * (v[p.a] - at.u[i]);
    }
    out[i] = oi;
  });
  for (std::size_t i = 0; i < out.size(); ++i) out[i] /= at.s[i];
  return out;
}

std::vector<Vec3> generalised_buoyancy(std::size_t n_dem, const std::vector<CouplingPair>& pairs, double mass,
                                       const std::vector<double>& s, const std::vector<Vec3>& a_fluid,
                                       double particle_volume) {
  std::vector<Vec3> f(n_dem, Vec3::Zero());
  by_dem_runs(pairs, [&](std::uint32_t i, std::size_t first, std::size_t last) {
    Vec3 fi = f[i];
    for (std::size_t q = first; q < last; ++q) fi += (mass * pairs[q].w) * a_fluid[pairs[q].a];  // (m/rho) W x rho a
    f[i] = fi;
  });
  for (std::size_t i = 0; i < n_dem; ++i) f[i] *= particle_volume / s[i];
  return f;
}

void add_back_coupling(const std::vector<CouplingPair>& pairs, const std::vector<Vec3>& force,
                       const std::vector<double>& s, const std::vector<double>& rho, std::vector<Vec3>& a_out) {
  for (const CouplingPair& p : pairs) a_out[p.a] -= (p.w / (rho[p.a] * s[p.i])) * force[p.i];
}

}  // namespace mrf
