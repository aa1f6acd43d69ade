// Verlet pair lists with a skin for the DEM scene: free-free pairs within the
// largest free-free interaction range and free-wall pairs within contact
// range, each plus the skin.
//
// Rebuilds. The imposed Couette flow u = gdot x e_z carries a particle by
// the affine displacement gamma x_ref e_z (gamma = the strain imposed since
// the build, signed), which is large near the walls but changes the
// separation of two particles only by gamma times its x component. With n_i
// the rest of particle i's displacement (its non-affine part) and
// r_c = range + skin, a pair farther apart than r_c at the build is still
// farther than `range` while
//     free-free:  2 max|n| + |gamma| r_c <= skin,
//     free-wall:    max|n| + |gamma| r_c <= skin
// (walls move affinely: |r + gamma r_x e_z| >= |r| (1 - |gamma|)). Each list
// is rebuilt when its own bound fails, so the skin is spent on what the
// particles do, not on where the flow carries them.
//
// Skin. A user value is kept. Otherwise (SkinPolicy::adaptive) each
// free-free build picks the skin that minimises the predicted time per step
// of the list sweep plus the amortised build,
//     (range + s)^3 [1 + beta (2 v + g (range + s)) / s],
// from the rates measured since the last build (v = max|n| per step,
// g = |gamma| per step) and beta = the time of one build over one force
// sweep of the same list (choose_skin). The rule depends only on the
// trajectory, so runs stay reproducible and resume bit for bit.
#pragma once
#include <cmath>
#include <vector>

#include "mrf/neighbors/cell_list.hpp"
#include "mrf/state.hpp"

namespace mrf {

// One build of both lists over one force sweep of the same lists: 13.8 ms
// against 2.5 ms of CPU time on the paper cell (BM_PaperNeighbourBuild and
// BM_PaperPairForces, 2-core EPYC, session 7).
inline constexpr double k_build_over_sweep = 5.5;

struct SkinPolicy {
  bool adaptive = false;     // false: the skin stays as given
  double min = 0, max = 0;   // m, range of an adaptive skin
  double build_over_sweep = k_build_over_sweep;
};

struct DemPairLists {
  double ff_range = 0;          // free-free interaction range without skin (m)
  double fw_range = 0;          // free-wall interaction range without skin (m); 0 = no walls
  double skin = 0;              // m
  SkinPolicy policy;
  PairRows ff;                  // free-free, row i holds the partners k > i
  std::vector<IndexPair> fw;    // (i free, k wall), sorted by i
  std::vector<Vec3> x_ref;      // free positions at the last free-free build
  std::vector<Vec3> x_ref_fw;   // free positions at the last free-wall build
  std::size_t walls_ref = 0;    // number of wall particles at the last free-wall build
  double strain_ff = 0;         // imposed strain since the free-free build (signed)
  double strain_fw = 0;         // imposed strain since the free-wall build (signed)
  long steps_ff = 0;            // steps since the free-free build
  long builds = 0;              // builds of either list
  long ff_builds = 0;           // builds of the free-free list
  // Checkpoints: the lists as built (their reference positions decide the
  // next rebuild, their order the round-off) and the skin in use; the
  // ranges and the policy come from the scene. One field list for both
  // directions (io/archive.hpp).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.ff.start, s.ff.k, s.fw, s.x_ref, s.x_ref_fw, s.walls_ref, s.skin, s.strain_ff, s.strain_fw, s.steps_ff,
          s.builds, s.ff_builds);
  }
};

// The bound above for any Verlet list: a list of pairs within `reach`
// (range + skin) at its build is spent when the pairs' largest non-affine
// closing (2 max|n| within one set of points, max|n_a| + max|n_b| between
// two) plus the imposed strain since the build times the reach exceeds the
// skin (m). The DEM lists, the implicit scheme's near list and the SPH pair
// cache all test this.
inline bool skin_spent(double nonaffine_closing, double strain, double reach, double skin) {
  return nonaffine_closing + std::abs(strain) * reach > skin;
}

// Largest displacement (m) of the points x from `ref` (minimum image).
double max_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box);
// Largest non-affine displacement (m): that of x from ref less the affine
// part strain * ref.x along z (see above).
double max_nonaffine_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box,
                                  double strain);

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin, const SkinPolicy& policy = {});

// One step of the imposed flow: d_strain = gdot dt (signed).
void advance_pair_lists(DemPairLists& lists, double d_strain);

// The skin (m) in [policy.min, policy.max] that minimises the predicted cost
// per step (see above) of lists of `range` (m), for particles moving
// non-affinely by `nonaffine_per_step` (m) and a strain of
// `strain_per_step` per step.
double choose_skin(const SkinPolicy& policy, double range, double nonaffine_per_step, double strain_per_step);

// Rebuilds the lists that may be stale (both on the first call, or when the
// number of particles changed); a list whose criterion still holds is kept.
void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box);
// Rebuilds both lists unconditionally.
void rebuild_all_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                            const Box& box);

// True when either list may be stale (see above).
bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box);

}  // namespace mrf
