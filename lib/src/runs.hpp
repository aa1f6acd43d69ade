// Runs of equal keys in a sorted list (internal to the library).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "parallel_blocks.hpp"

namespace mrf::detail {

// run(k, first, last) for each maximal run [first, last) of entries with
// the same key(entry) = k that starts in [lo, hi) (lo a run's start), in
// order. A loop that adds into out[k] per entry can instead hold out[k] in
// registers over the run and store it once: the same additions in the same
// order (bit for bit, as long as no entry of the run reaches out[k] another
// way), without the load that waits for the last entry's store.
template <class T, class Key, class Run>
void for_each_run(const std::vector<T>& entries, Key key, Run run, std::size_t lo, std::size_t hi) {
  for (std::size_t q = lo; q < hi;) {
    const std::size_t first = q;
    const std::uint32_t k = key(entries[q]);
    while (q < entries.size() && key(entries[q]) == k) ++q;
    run(k, first, q);
  }
}

// The same over every run.
template <class T, class Key, class Run>
void for_each_run(const std::vector<T>& entries, Key key, Run run) {
  for_each_run(entries, key, run, 0, entries.size());
}

// for_each_run on threads, in blocks of at least per_thread entries cut at
// run starts: each run (each key, in a list sorted by key) is one block's,
// so a run that writes only out[k] gives the same result bit for bit
// whatever the number of threads.
template <class T, class Key, class Run>
void for_each_run_on_threads(const std::vector<T>& entries, Key key, std::size_t per_thread, Run run) {
  const std::size_t n = entries.size();
  auto run_start = [&](std::size_t q) {  // the first run start at or after q
    if (q == 0 || q >= n) return std::min(q, n);
    const std::uint32_t k = key(entries[q - 1]);
    while (q < n && key(entries[q]) == k) ++q;
    return q;
  };
  for_blocks(n, block_count(n, per_thread), [&](std::size_t, std::size_t lo, std::size_t hi) {
    for_each_run(entries, key, run, run_start(lo), run_start(hi));
  });
}

}  // namespace mrf::detail
