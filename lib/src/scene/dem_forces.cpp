#include "mrf/scene/dem_forces.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/forces/dipole.hpp"
#include "mrf/forces/hertz.hpp"

namespace mrf {

namespace {

void add_free_pairs(const DemParams& p, const Box& box, FreeParticles& free,
                    const DemPairLists& lists, PairSums& s) {
  const double two_r = 2.0 * p.radius;
  const double rc2 = p.dipole_cutoff * p.dipole_cutoff;
  const bool magnetic = p.dipole_pref > 0;
  for (const auto& [i, k] : lists.ff) {
    const Vec3 r_ik = box.min_image(free.x[i] - free.x[k]);
    const double r2 = r_ik.squaredNorm();
    Vec3 f = Vec3::Zero();
    if (magnetic && r2 < rc2) {
      const Vec3 fd = dipole_force_x(r_ik, p.dipole_pref);
      s.virial_mag_xz += r_ik.x() * fd.z();
      // U = (mu0 m^2/4 pi r^3)(1 - 3 cos^2) = (pref/3) (1 - 3 c^2) / r^3
      s.energy_dipole += p.dipole_pref / 3.0 * (1.0 - 3.0 * r_ik.x() * r_ik.x() / r2) / (r2 * std::sqrt(r2));
      f += fd;
    }
    if (r2 < two_r * two_r) {
      const double r = std::sqrt(r2);
      const double h = two_r - r;
      const Vec3 fc = (hertz_force(h, p.hertz_k) / r) * r_ik;
      s.virial_con_xz += r_ik.x() * fc.z();
      s.energy_hertz += hertz_energy(h, p.hertz_k);
      s.max_overlap = std::max(s.max_overlap, h);
      f += fc;
    }
    free.f[i] += f;
    free.f[k] -= f;
  }
}

void add_wall_pairs(const DemParams& p, const Box& box, FreeParticles& free,
                    const WallParticles& walls, const DemPairLists& lists, PairSums& s) {
  const double two_r = 2.0 * p.radius;
  for (const auto& [i, k] : lists.fw) {
    const Vec3 r_ik = box.min_image(free.x[i] - walls.x[k]);
    const double r2 = r_ik.squaredNorm();
    if (r2 >= two_r * two_r) continue;
    const double r = std::sqrt(r2);
    const double h = two_r - r;
    const Vec3 fc = (hertz_force(h, p.hertz_k) / r) * r_ik;
    free.f[i] += fc;
    s.wall_fz[walls.side[k] > 0 ? 1 : 0] -= fc.z();
    s.virial_con_xz += r_ik.x() * fc.z();
    s.energy_hertz += hertz_energy(h, p.hertz_k);
    s.max_overlap = std::max(s.max_overlap, h);
  }
}

}  // namespace

PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists) {
  PairSums s;
  std::fill(free.f.begin(), free.f.end(), Vec3::Zero());
  add_free_pairs(p, box, free, lists, s);
  add_wall_pairs(p, box, free, walls, lists, s);
  s.pair_evaluations = static_cast<long>(lists.ff.size() + lists.fw.size());
  return s;
}

}  // namespace mrf
