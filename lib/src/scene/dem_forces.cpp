#include "mrf/scene/dem_forces.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "mrf/forces/dipole.hpp"
#include "mrf/forces/hertz.hpp"

namespace mrf {

void PairSums::merge(const PairSums& o) {
  wall_fz[0] += o.wall_fz[0];
  wall_fz[1] += o.wall_fz[1];
  virial_mag_xz += o.virial_mag_xz;
  virial_con_xz += o.virial_con_xz;
  max_overlap = std::max(max_overlap, o.max_overlap);
  energy_dipole += o.energy_dipole;
  energy_hertz += o.energy_hertz;
  pair_evaluations += o.pair_evaluations;
}

namespace {

// Free-free rows [row_begin, row_end) of the list, forces into f. Row i keeps
// x[i] and its force in registers; the minimum image is branch-free; one
// 1/sqrt(r^2) serves the dipole and the Hertz laws; the dipole energy is
// accumulated as (1 - 3 cos^2) / r^3 and scaled once at the end.
template <bool Magnetic>
void free_rows(const DemParams& p, const Box& box, const std::vector<Vec3>& x, const PairRows& rows,
               std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f, PairSums& s) {
  const double two_r = 2.0 * p.radius, four_r2 = two_r * two_r;
  const double rc2 = p.dipole_cutoff * p.dipole_cutoff;
  const double range2 = Magnetic ? std::max(rc2, four_r2) : four_r2;
  const double pref = p.dipole_pref;
  const MinImageYZ mi(box);
  const std::uint32_t* ks = rows.k.data();
  const Vec3* xs = x.data();
  Vec3* fs = f.data();
  double vir_mag = 0, e_dip = 0, vir_con = 0, e_hertz = 0, max_h = s.max_overlap;
  for (std::size_t i = row_begin; i < row_end; ++i) {
    const double xi = xs[i].x(), yi = xs[i].y(), zi = xs[i].z();
    double fxi = 0, fyi = 0, fzi = 0;
    for (std::uint32_t n = rows.start[i], e = rows.start[i + 1]; n < e; ++n) {
      const std::uint32_t k = ks[n];
      const double dx = xi - xs[k].x();
      const double dy = mi.wrap_y(yi - xs[k].y());
      const double dz = mi.wrap_z(zi - xs[k].z());
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 >= range2) continue;
      const double inv_r = 1.0 / std::sqrt(r2);
      double fx = 0, fy = 0, fz = 0;
      if constexpr (Magnetic) {
        // F = pref / r^4 [(1 - 5c^2) r^ + 2c x^], c = x / r (dipole_force_x)
        const double inv_r2 = inv_r * inv_r;
        const double c = dx * inv_r, c2 = c * c;
        const double sd = r2 < rc2 ? pref * inv_r2 * inv_r2 : 0.0;
        const double a = sd * (1.0 - 5.0 * c2) * inv_r;
        fx = a * dx + 2.0 * sd * c;
        fy = a * dy;
        fz = a * dz;
        vir_mag += dx * fz;
        e_dip += r2 < rc2 ? (1.0 - 3.0 * c2) * inv_r2 * inv_r : 0.0;
      }
      if (r2 < four_r2) {
        const double h = two_r - r2 * inv_r;
        if (h > 0) {
          const double sh = std::sqrt(h);
          const double fc = p.hertz_k * h * sh * inv_r;  // |F| / r
          vir_con += dx * (fc * dz);
          e_hertz += 0.4 * p.hertz_k * h * h * sh;
          max_h = std::max(max_h, h);
          fx += fc * dx;
          fy += fc * dy;
          fz += fc * dz;
        }
      }
      fxi += fx;
      fyi += fy;
      fzi += fz;
      fs[k].x() -= fx;
      fs[k].y() -= fy;
      fs[k].z() -= fz;
    }
    fs[i].x() += fxi;
    fs[i].y() += fyi;
    fs[i].z() += fzi;
  }
  s.virial_mag_xz += vir_mag;
  s.energy_dipole += pref / 3.0 * e_dip;  // U = (pref/3)(1 - 3 cos^2) / r^3
  s.virial_con_xz += vir_con;
  s.energy_hertz += e_hertz;
  s.max_overlap = max_h;
}

void free_pairs(const DemParams& p, const Box& box, const std::vector<Vec3>& x, const PairRows& rows,
                std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f, PairSums& s) {
  if (p.dipole_pref > 0)
    free_rows<true>(p, box, x, rows, row_begin, row_end, f, s);
  else
    free_rows<false>(p, box, x, rows, row_begin, row_end, f, s);
}

// First row of thread t's share: rows split so each thread gets about the
// same number of pairs (depends on the list alone: deterministic).
std::size_t row_chunk(const PairRows& rows, int t, int nt) {
  const std::size_t nrows = rows.rows();
  if (t == 0) return 0;
  if (t == nt) return nrows;
  const std::size_t target = rows.size() * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt);
  const auto it = std::lower_bound(rows.start.begin(), rows.start.end() - 1, static_cast<std::uint32_t>(target));
  return static_cast<std::size_t>(it - rows.start.begin());
}

void wall_pairs(const DemParams& p, const Box& box, const std::vector<Vec3>& x,
                const WallParticles& walls, const std::vector<IndexPair>& pairs, std::size_t begin,
                std::size_t end, std::vector<Vec3>& f, PairSums& s) {
  const double two_r = 2.0 * p.radius;
  const MinImageYZ mi(box);
  for (std::size_t n = begin; n < end; ++n) {
    const auto [i, k] = pairs[n];
    const Vec3 r_ik(x[i].x() - walls.x[k].x(), mi.wrap_y(x[i].y() - walls.x[k].y()),
                    mi.wrap_z(x[i].z() - walls.x[k].z()));
    const double r2 = r_ik.squaredNorm();
    if (r2 >= two_r * two_r) continue;
    const double r = std::sqrt(r2);
    const double h = two_r - r;
    const Vec3 fc = (hertz_force(h, p.hertz_k) / r) * r_ik;
    f[i] += fc;
    s.wall_fz[walls.side[k] > 0 ? 1 : 0] -= fc.z();
    s.virial_con_xz += r_ik.x() * fc.z();
    s.energy_hertz += hertz_energy(h, p.hertz_k);
    s.max_overlap = std::max(s.max_overlap, h);
  }
}

std::size_t chunk(std::size_t n, int t, int nt) { return n * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt); }

}  // namespace

PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf) {
  // Threads only where there is work for them: a parallel region costs more
  // than a few thousand pairs. The choice depends on the list size alone, so
  // results stay reproducible for a fixed thread count.
  constexpr std::size_t k_pairs_per_thread = 4096;
  const std::size_t work = lists.ff.size() + lists.fw.size();
  const int nt = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(omp_get_max_threads()),
                                                        std::max<std::size_t>(1, work / k_pairs_per_thread)));
  const std::size_t n = free.size();
  PairSums total;
  total.pair_evaluations = static_cast<long>(lists.ff.size() + lists.fw.size());
  if (nt == 1) {  // serial: accumulate straight into free.f
    std::fill(free.f.begin(), free.f.end(), Vec3::Zero());
    free_pairs(p, box, free.x, lists.ff, 0, lists.ff.rows(), free.f, total);
    wall_pairs(p, box, free.x, walls, lists.fw, 0, lists.fw.size(), free.f, total);
    return total;
  }
  buf.f.resize(static_cast<std::size_t>(nt));
  buf.sums.assign(static_cast<std::size_t>(nt), PairSums{});
#pragma omp parallel num_threads(nt)
  {
    const int t = omp_get_thread_num();
    auto& f = buf.f[static_cast<std::size_t>(t)];
    f.assign(n, Vec3::Zero());
    PairSums& s = buf.sums[static_cast<std::size_t>(t)];
    free_pairs(p, box, free.x, lists.ff, row_chunk(lists.ff, t, nt), row_chunk(lists.ff, t + 1, nt), f, s);
    wall_pairs(p, box, free.x, walls, lists.fw, chunk(lists.fw.size(), t, nt), chunk(lists.fw.size(), t + 1, nt), f, s);
#pragma omp barrier
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      Vec3 sum = buf.f[0][i];
      for (int u = 1; u < nt; ++u) sum += buf.f[static_cast<std::size_t>(u)][i];
      free.f[i] = sum;
    }
  }
  for (const PairSums& s : buf.sums) {  // thread order: deterministic
    const long pe = total.pair_evaluations;
    total.merge(s);
    total.pair_evaluations = pe;
  }
  return total;
}

PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists) {
  ForceBuffers buf;
  return compute_dem_forces(p, box, free, walls, lists, buf);
}

}  // namespace mrf
