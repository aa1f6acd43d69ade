// Deterministic parallel fills of one list (internal to the library).
#pragma once
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mrf::detail {

// Where block `blk` of `blocks` starts in [0, n) (block blk covers
// [block_bound(n, blk, blocks), block_bound(n, blk + 1, blocks))).
inline std::size_t block_bound(std::size_t n, std::size_t blk, std::size_t blocks) { return n * blk / blocks; }

// The same for rows of unequal work, row r's work start[r + 1] - start[r]
// (the row starts of a pair list, start.size() = rows + 1): the blocks hold
// equal shares of the total, a block ending at the first row start at or
// past its share.
inline std::size_t share_bound(const std::vector<std::uint32_t>& start, std::size_t blk, std::size_t blocks) {
  if (blk == 0 || start.empty()) return 0;
  if (blk >= blocks) return start.size() - 1;
  if (start.back() == 0) return block_bound(start.size() - 1, blk, blocks);  // no work to share: equal blocks
  const auto target = static_cast<std::uint32_t>(static_cast<std::size_t>(start.back()) * blk / blocks);
  return static_cast<std::size_t>(std::lower_bound(start.begin(), start.end() - 1, target) - start.begin());
}

// The number of blocks for a pass over n items: one per thread when
// n >= per_thread, else one.
inline int block_count(std::size_t n, std::size_t per_thread) {
  return n >= per_thread ? std::max(1, omp_get_max_threads()) : 1;
}

// body(blk, lo, hi) for each of `blocks` contiguous blocks of [0, n), on
// threads when blocks > 1. A body that writes only its own items (and its
// block's slot of a per-block result) gives the same result whatever the
// number of threads.
// bound(n, blk, blocks): where block blk starts (block_bound: equal blocks).
template <class Body, class Bound = decltype(&block_bound)>
void for_blocks(std::size_t n, int blocks, Body&& body, Bound bound = &block_bound) {
#pragma omp parallel for schedule(static, 1) if (blocks > 1)
  for (int blk = 0; blk < blocks; ++blk) {
    const auto b = static_cast<std::size_t>(blk), nb = static_cast<std::size_t>(blocks);
    body(b, bound(n, b, nb), bound(n, b + 1, nb));
  }
}

// body(i) for each i of [0, n), on threads when n >= per_thread: for a body
// that writes only item i, the result of the serial loop.
template <class Body>
void for_each_index(std::size_t n, std::size_t per_thread, Body&& body) {
  for_blocks(n, block_count(n, per_thread), [&](std::size_t, std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) body(i);
  });
}

// dst = src, in equal blocks on threads when src.size() >= per_thread.
template <class T>
void copy_on_threads(const std::vector<T>& src, std::vector<T>& dst, std::size_t per_thread) {
  const int blocks = block_count(src.size(), per_thread);
  if (blocks == 1) {
    dst = src;
    return;
  }
  dst.resize(src.size());
  for_blocks(src.size(), blocks, [&](std::size_t, std::size_t lo, std::size_t hi) {
    std::copy(src.begin() + static_cast<std::ptrdiff_t>(lo), src.begin() + static_cast<std::ptrdiff_t>(hi),
              dst.begin() + static_cast<std::ptrdiff_t>(lo));
  });
}

// The largest value of a pass and where it was taken, as a serial pass in
// order keeps it: the first strict maximum; nothing above 0 seen leaves
// v = 0 and at = npos. Blocks' results merged in block order give the
// serial result whatever the number of threads.
struct Largest {
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  double v = 0;
  std::size_t at = npos;
  void see(double x, std::size_t where) {
    if (x > v) v = x, at = where;
  }
  void merge(const Largest& o) {
    if (o.v > v) *this = o;
  }
};

// The largest of value(i) over [0, n) and the first i where it is taken, on
// threads when n >= per_thread.
template <class Value>
Largest largest_of(std::size_t n, std::size_t per_thread, Value&& value) {
  const int blocks = block_count(n, per_thread);
  std::vector<Largest> part(static_cast<std::size_t>(blocks));
  for_blocks(n, blocks, [&](std::size_t b, std::size_t lo, std::size_t hi) {
    Largest best;  // a local, stored once: the blocks' slots share a cache line
    for (std::size_t i = lo; i < hi; ++i) best.see(value(i), i);
    part[b] = best;
  });
  Largest best;
  for (const Largest& p : part) best.merge(p);
  return best;
}

// body(lo, hi, mine) over [0, n) in contiguous blocks, one per thread when
// n >= per_thread, each filling its own list; the lists are joined into
// `out` in block order, so the result is the same whatever the number of
// threads. Returns where each block's entries begin in `out`, one per block
// (the blocks' ranges: `bound`, block_bound unless given).
template <class T, class Body, class Bound = decltype(&block_bound)>
std::vector<std::size_t> in_blocks(std::size_t n, std::size_t per_thread, std::vector<T>& out, Body&& body,
                                   Bound bound = &block_bound) {
  const int blocks = block_count(n, per_thread);
  std::vector<std::vector<T>> part(static_cast<std::size_t>(blocks));
  for_blocks(
      n, blocks,
      [&](std::size_t b, std::size_t lo, std::size_t hi) {
        if (blocks == 1) {
          out.clear();
          body(lo, hi, out);
          return;
        }
        // On threads each block fills a vector of its own (block 0 takes
        // out's storage) and hands it back at the end: a push_back into out
        // itself would write its header, next to data the other threads read
        // in their loops, on every item.
        std::vector<T> mine;
        mine.swap(b == 0 ? out : part[b]);
        mine.clear();
        body(lo, hi, mine);
        mine.swap(b == 0 ? out : part[b]);
      },
      bound);
  std::vector<std::size_t> begin(static_cast<std::size_t>(blocks), 0);
  for (int blk = 1; blk < blocks; ++blk) {
    begin[static_cast<std::size_t>(blk)] = out.size();
    out.insert(out.end(), part[static_cast<std::size_t>(blk)].begin(), part[static_cast<std::size_t>(blk)].end());
  }
  return begin;
}

// The same with two lists filled side by side (entry k of one belongs to
// entry k of the other): body(lo, hi, mine_t, mine_u), both joined in block
// order.
template <class T, class U, class Body>
void in_blocks2(std::size_t n, std::size_t per_thread, std::vector<T>& out_t, std::vector<U>& out_u, Body&& body) {
  const int blocks = block_count(n, per_thread);
  std::vector<std::vector<T>> part_t(static_cast<std::size_t>(blocks));
  std::vector<std::vector<U>> part_u(static_cast<std::size_t>(blocks));
  for_blocks(n, blocks, [&](std::size_t b, std::size_t lo, std::size_t hi) {
    std::vector<T> mt;  // the block's own vectors, as in in_blocks
    std::vector<U> mu;
    mt.swap(b == 0 ? out_t : part_t[b]);
    mu.swap(b == 0 ? out_u : part_u[b]);
    mt.clear();
    mu.clear();
    body(lo, hi, mt, mu);
    mt.swap(b == 0 ? out_t : part_t[b]);
    mu.swap(b == 0 ? out_u : part_u[b]);
  });
  for (std::size_t blk = 1; blk < static_cast<std::size_t>(blocks); ++blk) {
    out_t.insert(out_t.end(), part_t[blk].begin(), part_t[blk].end());
    out_u.insert(out_u.end(), part_u[blk].begin(), part_u[blk].end());
  }
}

}  // namespace mrf::detail
