// Runs of equal keys in a sorted list (internal to the library).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mrf::detail {

// run(k, first, last) for each maximal run [first, last) of entries with
// the same key(entry) = k, in order. A loop that adds into out[k] per entry
// can instead hold out[k] in registers over the run and store it once: the
// same additions in the same order (bit for bit, as long as no entry of the
// run reaches out[k] another way), without the load that waits for the
// last entry's store.
template <class T, class Key, class Run>
void for_each_run(const std::vector<T>& entries, Key key, Run run) {
  for (std::size_t q = 0; q < entries.size();) {
    const std::size_t first = q;
    const std::uint32_t k = key(entries[q]);
    while (q < entries.size() && key(entries[q]) == k) ++q;
    run(k, first, q);
  }
}

}  // namespace mrf::detail
