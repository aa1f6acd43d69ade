// The coupling pairs by DEM particle (internal to the library).
#pragma once
#include <cstddef>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "runs.hpp"

namespace mrf::detail {

inline constexpr std::size_t k_exchange_pairs_per_thread = 8192;  // the least a thread takes

// run(i, first, last) over the runs of pairs of one DEM particle i (pairs
// come sorted by i): a sum over a run is held in registers and added into
// its array once; on threads by blocks of whole runs, so a run that writes
// only its own i gives the same result whatever the threads.
template <class Run>
void by_dem_runs(const std::vector<CouplingPair>& pairs, Run run) {
  for_each_run_on_threads(pairs, [](const CouplingPair& p) { return p.i; }, k_exchange_pairs_per_thread, run);
}

}  // namespace mrf::detail
