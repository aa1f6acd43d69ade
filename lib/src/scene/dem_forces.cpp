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

// Free-free pairs [begin, end) of the list, forces into f.
void free_pairs(const DemParams& p, const Box& box, const std::vector<Vec3>& x,
                const std::vector<IndexPair>& pairs, std::size_t begin, std::size_t end,
                std::vector<Vec3>& f, PairSums& s) {
  const double two_r = 2.0 * p.radius, four_r2 = two_r * two_r;
  const double rc2 = p.dipole_cutoff * p.dipole_cutoff;
  const bool magnetic = p.dipole_pref > 0;
  for (std::size_t n = begin; n < end; ++n) {
    const auto [i, k] = pairs[n];
    const Vec3 r_ik = box.min_image(x[i] - x[k]);
    const double r2 = r_ik.squaredNorm();
    if (r2 >= rc2 && r2 >= four_r2) continue;
    Vec3 fik = Vec3::Zero();
    if (magnetic && r2 < rc2) {
      const Vec3 fd = dipole_force_x(r_ik, p.dipole_pref);
      s.virial_mag_xz += r_ik.x() * fd.z();
      // U = (pref/3)(1 - 3 cos^2) / r^3
      s.energy_dipole += p.dipole_pref / 3.0 * (1.0 - 3.0 * r_ik.x() * r_ik.x() / r2) / (r2 * std::sqrt(r2));
      fik = fd;
    }
    if (r2 < four_r2) {
      const double r = std::sqrt(r2);
      const double h = two_r - r;
      const Vec3 fc = (hertz_force(h, p.hertz_k) / r) * r_ik;
      s.virial_con_xz += r_ik.x() * fc.z();
      s.energy_hertz += hertz_energy(h, p.hertz_k);
      s.max_overlap = std::max(s.max_overlap, h);
      fik += fc;
    }
    f[i] += fik;
    f[k] -= fik;
  }
}

void wall_pairs(const DemParams& p, const Box& box, const std::vector<Vec3>& x,
                const WallParticles& walls, const std::vector<IndexPair>& pairs, std::size_t begin,
                std::size_t end, std::vector<Vec3>& f, PairSums& s) {
  const double two_r = 2.0 * p.radius;
  for (std::size_t n = begin; n < end; ++n) {
    const auto [i, k] = pairs[n];
    const Vec3 r_ik = box.min_image(x[i] - walls.x[k]);
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
    free_pairs(p, box, free.x, lists.ff, 0, lists.ff.size(), free.f, total);
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
    free_pairs(p, box, free.x, lists.ff, chunk(lists.ff.size(), t, nt), chunk(lists.ff.size(), t + 1, nt), f, s);
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
