#include "mrf/scene/dem_forces.hpp"

#include <omp.h>

#include <algorithm>

#include "parallel_blocks.hpp"

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

DemPairLaws<> dem_pair_laws(const DemParams& p) {
  return {DipoleX{p.dipole_pref}, HertzPair{p.hertz_k, 2.0 * p.radius}, p.dipole_cutoff, p.dipole_pref > 0};
}

namespace detail {

// Rows split so each thread gets about the same number of pairs (depends on
// the list alone: deterministic).
std::size_t row_chunk(const PairRows& rows, int t, int nt) {
  return detail::share_bound(rows.start, static_cast<std::size_t>(t), static_cast<std::size_t>(nt));
}

std::size_t chunk(std::size_t n, int t, int nt) { return n * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt); }

// Threads only where there is work for them: a parallel region costs more
// than a few thousand pairs. The choice depends on the list size alone, so
// results stay reproducible for a fixed thread count.
int pair_threads(const DemPairLists& lists) {
  constexpr std::size_t k_pairs_per_thread = 4096;
  const std::size_t work = lists.ff.size() + lists.fw.size();
  return static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(omp_get_max_threads()),
                                                std::max<std::size_t>(1, work / k_pairs_per_thread)));
}

}  // namespace detail

PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf) {
  return compute_pair_forces(dem_pair_laws(p), box, free, walls, lists, buf);
}

PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists) {
  ForceBuffers buf;
  return compute_dem_forces(p, box, free, walls, lists, buf);
}

}  // namespace mrf
