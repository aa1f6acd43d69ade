// Pair forces of the DEM scene (dipole + Hertz between free particles, Hertz
// between free and wall spheres) and the sums the stress observables need.
// The laws are the evaluators of forces/ (DipoleX, HertzPair); this file is
// the loop around them (STYLE.md §1, §4): minimum image, cut-off, +-F,
// virial and sums. The scene's own laws run its free-free rows on the
// vector units (free_rows_simd, scene/pair_kernel_simd.cpp, the same law
// templates of forces/laws-inl.h), and so do the quasi-static driver's
// (shifted-force dipole); other evaluators (tests) run the scalar free_rows. OpenMP over the half pair lists with one force buffer per
// thread, reduced in thread order: bitwise reproducible for a fixed thread
// count.
#pragma once
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/forces/dipole.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/state.hpp"

namespace mrf {

struct DipoleXShiftedForce;  // quasistatic/shifted_dipole.hpp

struct PairSums {
  std::array<double, 2> wall_fz{0, 0};  // z-force of the particles on the lower [0] / upper [1] wall (N)
  double virial_mag_xz = 0;             // sum over pairs of r_ik,x F_ik,z, dipole part (N m)
  double virial_con_xz = 0;             // same, Hertz part (N m)
  double max_overlap = 0;               // m
  double energy_dipole = 0;             // J (within the cutoff, unshifted)
  double energy_hertz = 0;              // J
  long pair_evaluations = 0;            // pairs in the lists visited

  void merge(const PairSums& o);
};

// Per-thread force buffers, kept between steps so the hot loop does not allocate.
struct ForceBuffers {
  std::vector<std::vector<Vec3>> f;
  std::vector<PairSums> sums;
};

// What the loop evaluates. A template on the evaluators so that the loop the
// scene runs can be run by a test with another evaluator; the scene uses
// dem_pair_laws(). Contact serves free-free and free-wall pairs alike (walls
// are spheres of the same radius, REFERENCE.md §2).
template <class Dipole = DipoleX, class Contact = HertzPair>
struct DemPairLaws {
  Dipole dipole;         // equal moments along +x, REFERENCE.md Eq. 3
  Contact contact;       // REFERENCE.md Eq. 2; its sum_radii is the contact cut-off
  double dipole_cutoff;  // m
  bool magnetic;         // false: the dipole term is not evaluated at all
};

DemPairLaws<> dem_pair_laws(const DemParams& p);

// Overwrites free.f with the pair forces and returns the sums.
template <class Dipole, class Contact>
PairSums compute_pair_forces(const DemPairLaws<Dipole, Contact>& laws, const Box& box, FreeParticles& free,
                             const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf);

// The instruction set the vectorised pair kernel runs on here ("AVX3" for
// AVX-512, "AVX2", "SSE4", ...).
const char* pair_kernel_target();

// The scene's laws: compute_pair_forces(dem_pair_laws(p), ...).
PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf);
PairSums compute_dem_forces(const DemParams& p, const Box& box, FreeParticles& free,
                            const WallParticles& walls, const DemPairLists& lists);

// ---- the loop (a template, hence here) ----

namespace detail {

// First row of thread t's share of the free-free rows, and of a flat range.
std::size_t row_chunk(const PairRows& rows, int t, int nt);
std::size_t chunk(std::size_t n, int t, int nt);
// Threads worth starting for this many pairs (depends on the lists alone).
int pair_threads(const DemPairLists& lists);

// Sums of the pair terms of a share of rows (dipole energy without its
// constant, see DipoleX::energy_scale).
struct PairTally {
  double vir_mag = 0, e_dip = 0, vir_con = 0, e_hertz = 0, max_h = 0;
};

// The force on i of one free-free pair in range, (dx, dy, dz) = r_ik with
// r2 = |r_ik|^2, its virial and energy terms added to t: the scalar loop's
// pair, which the vector kernel's row tails run too.
template <bool Magnetic, bool DipoleTest, class Dipole, class Contact>
inline Vec3 pair_force(const Dipole& dipole, const Contact& contact, double rc2, double contact2, double dx,
                       double dy, double dz, double r2, PairTally& t) {
  const double inv_r = 1.0 / std::sqrt(r2);
  Vec3 fik = Vec3::Zero();
  if constexpr (Magnetic) {
    if (!DipoleTest || r2 < rc2) {
      t.e_dip += dipole.eval(dx, dy, dz, inv_r, fik);
      t.vir_mag += dx * fik.z();
    }
  }
  // r2 < contact2 first: it is known before the sqrt, so the rare
  // contact branch is resolved early (the evaluator's own h > 0 test
  // waits for 1/r).
  HertzContact c;
  if (r2 < contact2 && contact.eval(r2, inv_r, c)) {
    const Vec3 fc(c.f_over_r * dx, c.f_over_r * dy, c.f_over_r * dz);
    t.vir_con += dx * fc.z();
    t.e_hertz += c.energy;
    t.max_h = std::max(t.max_h, c.overlap);
    fik += fc;
  }
  return fik;
}

// Free-free rows [row_begin, row_end), forces into f. Row i keeps x[i] and
// its force in registers; the minimum image is branch-free; one 1/sqrt(r^2)
// serves both evaluators; the dipole energy is summed without its constant
// and scaled once at the end (DipoleX::energy_scale). DipoleTest is false
// when the dipole cut-off is the range of the loop (cut-off >= contact
// distance, as scene input requires): then every pair in range is inside
// it, and the test per pair costs 2 % of the loop.
template <bool Magnetic, bool DipoleTest, class Dipole, class Contact>
void free_rows(const DemPairLaws<Dipole, Contact>& laws, const Box& box, const std::vector<Vec3>& x,
               const PairRows& rows, std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f,
               PairSums& s) {
  // Local copies: through the reference the compiler must assume that the
  // force stores may change the parameters and reload them every pair.
  const Dipole dipole = laws.dipole;
  const Contact contact = laws.contact;
  const double contact2 = contact.sum_radii * contact.sum_radii;
  const double rc2 = laws.dipole_cutoff * laws.dipole_cutoff;
  const double range2 = Magnetic ? std::max(rc2, contact2) : contact2;
  const MinImageYZ mi(box);
  const std::uint32_t* ks = rows.k.data();
  const Vec3* xs = x.data();
  Vec3* fs = f.data();
  PairTally t;
  t.max_h = s.max_overlap;
  for (std::size_t i = row_begin; i < row_end; ++i) {
    const Vec3 xi = xs[i];
    Vec3 fi = Vec3::Zero();
    for (std::uint32_t n = rows.start[i], e = rows.start[i + 1]; n < e; ++n) {
      const std::uint32_t k = ks[n];
      const double dx = xi.x() - xs[k].x();
      const double dy = mi.wrap_y(xi.y() - xs[k].y());
      const double dz = mi.wrap_z(xi.z() - xs[k].z());
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 >= range2) continue;
      const Vec3 fik = pair_force<Magnetic, DipoleTest>(dipole, contact, rc2, contact2, dx, dy, dz, r2, t);
      fi += fik;
      fs[k] -= fik;
    }
    fs[i] += fi;
  }
  s.virial_mag_xz += t.vir_mag;
  if constexpr (Magnetic) s.energy_dipole += dipole.energy_scale() * t.e_dip;
  s.virial_con_xz += t.vir_con;
  s.energy_hertz += t.e_hertz;
  s.max_overlap = t.max_h;
}

// Free-wall pairs [begin, end); only the free sphere's force is kept, the
// wall's side goes into wall_fz.
template <class Dipole, class Contact>
void wall_pairs(const DemPairLaws<Dipole, Contact>& laws, const Box& box, const std::vector<Vec3>& x,
                const WallParticles& walls, const std::vector<IndexPair>& pairs, std::size_t begin,
                std::size_t end, std::vector<Vec3>& f, PairSums& s) {
  const Contact contact = laws.contact;  // local, as in free_rows
  const double contact2 = contact.sum_radii * contact.sum_radii;
  const MinImageYZ mi(box);
  for (std::size_t n = begin; n < end; ++n) {
    const auto [i, k] = pairs[n];
    const double dx = x[i].x() - walls.x[k].x();
    const double dy = mi.wrap_y(x[i].y() - walls.x[k].y());
    const double dz = mi.wrap_z(x[i].z() - walls.x[k].z());
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (r2 >= contact2) continue;
    HertzContact c;
    if (!contact.eval(r2, 1.0 / std::sqrt(r2), c)) continue;
    const Vec3 fc(c.f_over_r * dx, c.f_over_r * dy, c.f_over_r * dz);
    f[i] += fc;
    s.wall_fz[walls.side[k] > 0 ? 1 : 0] -= fc.z();
    s.virial_con_xz += dx * fc.z();
    s.energy_hertz += c.energy;
    s.max_overlap = std::max(s.max_overlap, c.overlap);
  }
}

// free_rows<true, false> on the vector units, the best instruction set of
// the machine chosen at run time (pair_kernel_simd.cpp): the scene's laws,
// and the quasi-static driver's (shifted-force dipole + Hertz).
void free_rows_simd(const DemPairLaws<>& laws, const Box& box, const std::vector<Vec3>& x, const PairRows& rows,
                    std::size_t row_begin, std::size_t row_end, std::vector<Vec3>& f, PairSums& s);
void free_rows_simd_shifted(const DemPairLaws<DipoleXShiftedForce, HertzPair>& laws, const Box& box,
                            const std::vector<Vec3>& x, const PairRows& rows, std::size_t row_begin,
                            std::size_t row_end, std::vector<Vec3>& f, PairSums& s);

template <class Dipole, class Contact>
void pair_share(const DemPairLaws<Dipole, Contact>& laws, const Box& box, const FreeParticles& free,
                const WallParticles& walls, const DemPairLists& lists, int t, int nt, std::vector<Vec3>& f,
                PairSums& s) {
  const std::size_t r0 = row_chunk(lists.ff, t, nt), r1 = row_chunk(lists.ff, t + 1, nt);
  if (!laws.magnetic)
    free_rows<false, false>(laws, box, free.x, lists.ff, r0, r1, f, s);
  else if (laws.dipole_cutoff >= laws.contact.sum_radii) {
    if constexpr (std::is_same_v<Dipole, DipoleX> && std::is_same_v<Contact, HertzPair>)
      free_rows_simd(laws, box, free.x, lists.ff, r0, r1, f, s);
    else if constexpr (std::is_same_v<Dipole, DipoleXShiftedForce> && std::is_same_v<Contact, HertzPair>)
      free_rows_simd_shifted(laws, box, free.x, lists.ff, r0, r1, f, s);
    else
      free_rows<true, false>(laws, box, free.x, lists.ff, r0, r1, f, s);
  }
  else
    free_rows<true, true>(laws, box, free.x, lists.ff, r0, r1, f, s);
  const std::size_t n = lists.fw.size();
  wall_pairs(laws, box, free.x, walls, lists.fw, chunk(n, t, nt), chunk(n, t + 1, nt), f, s);
}

}  // namespace detail

template <class Dipole, class Contact>
PairSums compute_pair_forces(const DemPairLaws<Dipole, Contact>& laws, const Box& box, FreeParticles& free,
                             const WallParticles& walls, const DemPairLists& lists, ForceBuffers& buf) {
  const int nt = detail::pair_threads(lists);
  const std::size_t n = free.size();
  PairSums total;
  total.pair_evaluations = static_cast<long>(lists.ff.size() + lists.fw.size());
  if (nt == 1) {  // serial: accumulate straight into free.f
    std::fill(free.f.begin(), free.f.end(), Vec3::Zero());
    detail::pair_share(laws, box, free, walls, lists, 0, 1, free.f, total);
    return total;
  }
  buf.f.resize(static_cast<std::size_t>(nt));
  buf.sums.assign(static_cast<std::size_t>(nt), PairSums{});
  int team = nt;
#pragma omp parallel num_threads(nt)
  {
    // the team OpenMP gave (it may be smaller than asked) shares the rows
    const int t = omp_get_thread_num(), nteam = omp_get_num_threads();
    if (t == 0) team = nteam;
    auto& f = buf.f[static_cast<std::size_t>(t)];
    f.assign(n, Vec3::Zero());
    detail::pair_share(laws, box, free, walls, lists, t, nteam, f, buf.sums[static_cast<std::size_t>(t)]);
#pragma omp barrier
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      Vec3 sum = buf.f[0][i];
      for (int u = 1; u < nteam; ++u) sum += buf.f[static_cast<std::size_t>(u)][i];
      free.f[i] = sum;
    }
  }
  buf.sums.resize(static_cast<std::size_t>(team));
  for (const PairSums& s : buf.sums) {  // thread order: deterministic
    const long pe = total.pair_evaluations;
    total.merge(s);
    total.pair_evaluations = pe;
  }
  return total;
}

}  // namespace mrf
