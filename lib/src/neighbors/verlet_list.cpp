#include "mrf/neighbors/verlet_list.hpp"

#include <algorithm>
#include <cmath>

#include "parallel_blocks.hpp"

namespace mrf {

namespace {
constexpr std::size_t k_spheres_per_thread = 2048;  // of the displacement passes
}

double max_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box) {
  const MinImageYZ mi(box);
  return std::sqrt(
      detail::largest_of(x.size(), k_spheres_per_thread, [&](std::size_t i) { return mi.norm2(x[i], ref[i]); }).v);
}

double max_nonaffine_displacement(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const Box& box,
                                  double strain) {
  const MinImageYZ mi(box);
  return std::sqrt(detail::largest_of(x.size(), k_spheres_per_thread, [&](std::size_t i) {
                     Vec3 d = mi.delta(x[i], ref[i]);
                     d.z() -= strain * ref[i].x();
                     return d.squaredNorm();
                   }).v);
}

double choose_skin(const SkinPolicy& policy, double range, double nonaffine_per_step, double strain_per_step) {
  // Cost per step of a skin s relative to an infinitely long-lived list of
  // the same length; 200 log-spaced candidates resolve the optimum to 2 %.
  const auto cost = [&](double s) {
    const double rc = range + s;
    return rc * rc * rc * (1.0 + policy.build_over_sweep * (2.0 * nonaffine_per_step + strain_per_step * rc) / s);
  };
  if (!(policy.max > policy.min) || !(policy.min > 0)) return policy.min;
  constexpr int k_candidates = 200;
  double best = policy.min, best_cost = cost(policy.min);
  for (int j = 1; j <= k_candidates; ++j) {
    const double s = policy.min * std::pow(policy.max / policy.min, static_cast<double>(j) / k_candidates);
    const double c = cost(s);
    if (c < best_cost) best = s, best_cost = c;
  }
  return best;
}

namespace {

// The free-free list's state: unbuilt (or built for another number of
// particles), or its largest non-affine displacement since the build.
struct FreeFreeMotion {
  bool unbuilt = true;
  double nonaffine = 0;  // m
};

FreeFreeMotion ff_motion(const DemPairLists& l, const FreeParticles& free, const Box& box) {
  if (l.builds == 0 || l.x_ref.size() != free.size() || l.ff.rows() != free.size()) return {};
  return {false, max_nonaffine_displacement(free.x, l.x_ref, box, l.strain_ff)};
}

bool ff_stale(const DemPairLists& l, const FreeFreeMotion& m) {
  return m.unbuilt || skin_spent(2.0 * m.nonaffine, l.strain_ff, l.ff_range + l.skin, l.skin);
}

bool fw_stale(const DemPairLists& l, const FreeParticles& free, std::size_t n_walls, const Box& box) {
  if (l.fw_range <= 0) return false;
  if (l.builds == 0 || l.x_ref_fw.size() != free.size() || l.walls_ref != n_walls) return true;
  return skin_spent(max_nonaffine_displacement(free.x, l.x_ref_fw, box, l.strain_fw), l.strain_fw,
                    l.fw_range + l.skin, l.skin);
}

// An adaptive skin is chosen from the rates since the last free-free
// build; true when it changed (the free-wall list, built with the old
// skin, must then be rebuilt too).
bool adapt_skin(DemPairLists& l, const FreeFreeMotion& m) {
  if (!l.policy.adaptive || l.steps_ff <= 0 || m.unbuilt) return false;
  const double steps = static_cast<double>(l.steps_ff);
  const double skin = choose_skin(l.policy, l.ff_range, m.nonaffine / steps, std::abs(l.strain_ff) / steps);
  if (skin == l.skin) return false;
  l.skin = skin;
  return true;
}

void build_ff(DemPairLists& lists, const FreeParticles& free, const Box& box) {
  self_pair_rows(free.x, box, lists.ff_range + lists.skin, lists.ff);
  lists.x_ref = free.x;
  lists.strain_ff = 0;
  lists.steps_ff = 0;
  ++lists.ff_builds;
}

void build_fw(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls, const Box& box) {
  lists.fw.clear();
  if (lists.fw_range > 0) lists.fw = cross_pairs(free.x, walls.x, box, lists.fw_range + lists.skin);
  lists.x_ref_fw = free.x;
  lists.walls_ref = walls.size();
  lists.strain_fw = 0;
}
}  // namespace

DemPairLists make_pair_lists(double ff_range, double fw_range, double skin, const SkinPolicy& policy) {
  DemPairLists l;
  l.ff_range = ff_range;
  l.fw_range = fw_range;
  l.skin = policy.adaptive ? std::clamp(skin, policy.min, policy.max) : skin;
  l.policy = policy;
  return l;
}

void advance_pair_lists(DemPairLists& lists, double d_strain) {
  lists.strain_ff += d_strain;
  lists.strain_fw += d_strain;
  ++lists.steps_ff;
}

void build_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                      const Box& box) {
  const FreeFreeMotion m = ff_motion(lists, free, box);
  const bool ff = ff_stale(lists, m);
  const bool resized = ff && adapt_skin(lists, m);
  const bool fw = resized || fw_stale(lists, free, walls.size(), box) || (lists.fw_range <= 0 && !lists.fw.empty());
  if (ff) build_ff(lists, free, box);
  if (fw) build_fw(lists, free, walls, box);
  if (ff || fw) ++lists.builds;
}

void rebuild_all_pair_lists(DemPairLists& lists, const FreeParticles& free, const WallParticles& walls,
                            const Box& box) {
  build_ff(lists, free, box);
  build_fw(lists, free, walls, box);
  ++lists.builds;
}

bool needs_rebuild(const DemPairLists& lists, const FreeParticles& free, const Box& box) {
  return ff_stale(lists, ff_motion(lists, free, box)) || fw_stale(lists, free, lists.walls_ref, box);
}

}  // namespace mrf
