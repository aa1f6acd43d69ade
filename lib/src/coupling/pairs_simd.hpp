// The range test of the coupling pairs over their Verlet candidates
// (internal to the library; coupling_pairs_of in exchange.cpp is its one
// caller), vectorised in pairs_simd.cpp.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mrf/coupling/exchange.hpp"

namespace mrf::detail {

struct InRangeQuery {
  const IndexPair* candidates;    // (DEM i, SPH a)
  const double* dem_x;            // x, y, z of each DEM point, packed (a std::vector<Vec3>'s data)
  const double* sph_x;            // the same for the SPH particles
  double ly, lz, inv_ly, inv_lz;  // periodic lengths (m) and their inverses
  double rc2;                     // the support squared (m^2)
  bool ky, kz;                    // a second image can be in range along y (ly < 2 rc), along z
  bool with_sep;                  // also the separations
};

// The entries in range, in candidate order, each periodic image its own
// entry after the minimum one (y image, z image, both): (i, a) as the
// candidates hold them, r^2 and, with_sep, the separation x_i - x_a of the
// image, in the first n places of each vector (the vectors only grow, so
// that a reused InRange writes no memory twice).
struct InRange {
  std::size_t n = 0;
  std::vector<std::uint64_t> ends;
  std::vector<double> r2, sx, sy, sz;
};

void in_range_candidates(const InRangeQuery& q, std::size_t lo, std::size_t hi, InRange& out);

}  // namespace mrf::detail
