// The implicit step's passes that run on threads give the serial results bit
// for bit (the contact search, the contact forces at x_n, the free-wall list,
// the displacement tests of the lists), on the paper cell after some
// implicit steps: on 1, 2 and 3 threads and on a team of one where two were
// asked. Each pass is cut into blocks whose results are joined or merged in
// order (lib/src/parallel_blocks.hpp); a block that skipped or repeated items
// would change a list's length or a sum.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdio>
#include <functional>
#include <vector>

#include "mrf/integrate/implicit_contact.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {
namespace {

constexpr int k_runs = 4;  // 1, 2 and 3 threads; 2 asked with a team of one

// fn() on the thread counts of the runs
template <class T>
std::vector<T> on_threads(const std::function<T()>& fn) {
  std::vector<T> out;
  for (int t = 0; t < k_runs; ++t) {
    const int saved = omp_get_max_threads(), saved_levels = omp_get_max_active_levels();
    omp_set_num_threads(t < 3 ? t + 1 : 2);
    if (t == 3) omp_set_max_active_levels(0);  // every team of one thread
    out.push_back(fn());
    omp_set_num_threads(saved);
    omp_set_max_active_levels(saved_levels);
  }
  return out;
}

struct Paper {
  DemParams p;
  DemModel model;
};

Paper paper_after_steps() {
  const LoadedScene sc =
      load_scene(MRF_SOURCE_DIR "/experiments/scenes/paper_dem_stokes.toml", {"numerics.threads=1"});
  const DemParams p = dem_params(sc.config);
  Paper out{p, DemModel(build_shear_cell(sc.config), p, IntegratorId::implicit,
                        smallest(dem_limits(p, sc.config.gap, IntegratorId::implicit)))};
  for (int n = 0; n < 30; ++n) out.model.step();
  return out;
}

bool same_pairs(const std::vector<ContactPair>& a, const std::vector<ContactPair>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t n = 0; n < a.size(); ++n)
    if (a[n].i != b[n].i || a[n].k != b[n].k || a[n].wall != b[n].wall) return false;
  return true;
}

TEST(ThreadedPasses, ContactSearchAndForcesEqualTheSerialOnes) {
  Paper s = paper_after_steps();
  const ShearCell& c = s.model.cell();
  const double r = s.p.radius, margin = 0.2 * r;
  std::vector<ContactPair> near;
  near_pairs(s.model.lists().ff, c.free.x, c.box, 2.0 * r + margin + 0.5 * r, near);
  const auto candidates = on_threads<std::vector<ContactPair>>([&] {
    std::vector<ContactPair> out;
    contact_candidates(near, s.model.lists().fw, c.free.x, c.walls, c.box, r, margin, out);
    return out;
  });
  const std::vector<ContactPair>& pairs = candidates[0];
  std::size_t walls = 0;
  for (const ContactPair& pc : pairs) walls += pc.wall ? 1 : 0;
  std::printf("%zu candidates (%zu with a wall), free-wall list %zu\n", pairs.size(), walls,
              s.model.lists().fw.size());
  ASSERT_GE(pairs.size(), 4096u) << "enough candidates for a block per thread";
  ASSERT_GE(s.model.lists().fw.size(), 4096u) << "enough free-wall pairs for a block per thread";
  ASSERT_GT(walls, 0u);
  for (int t = 1; t < k_runs; ++t) EXPECT_TRUE(same_pairs(pairs, candidates[t])) << "run " << t;

  struct Forces {
    std::vector<Vec3> f;
    double h_max;
  };
  const auto forces = on_threads<Forces>([&] {
    Forces out;
    out.h_max = contact_forces(pairs, c.free.x, c.walls, c.box, r, s.p.hertz_k, out.f);
    return out;
  });
  std::size_t pushed = 0;
  for (const Vec3& f : forces[0].f) pushed += f.squaredNorm() > 0 ? 1 : 0;
  EXPECT_GT(pushed, c.free.size() / 4) << "spheres in contact";
  EXPECT_GT(forces[0].h_max, 0.0);
  for (int t = 1; t < k_runs; ++t) {
    EXPECT_EQ(forces[0].h_max, forces[t].h_max) << "run " << t;
    for (std::size_t i = 0; i < forces[0].f.size(); ++i) ASSERT_EQ(forces[0].f[i], forces[t].f[i]) << "sphere " << i;
  }
}

TEST(ThreadedPasses, WallListAndDisplacementsEqualTheSerialOnes) {
  Paper s = paper_after_steps();
  const ShearCell& c = s.model.cell();
  const auto lists = on_threads<std::vector<IndexPair>>([&] { return cross_pairs(c.free.x, c.walls.x, c.box, 3.0 * s.p.radius); });
  ASSERT_GE(c.free.size(), 2048u) << "enough spheres for a block per thread";
  EXPECT_GT(lists[0].size(), 1000u);
  for (int t = 1; t < k_runs; ++t) EXPECT_EQ(lists[0], lists[t]) << "run " << t;
  // every sphere displaced by its own amount, the largest planted at the
  // last sphere (the last block's last item) and, in a second test, the first
  std::vector<Vec3> ref = c.free.x;
  for (std::size_t i = 0; i < ref.size(); ++i) ref[i].y() += 1e-8 * static_cast<double>((i * 7919) % 1000);
  for (const std::size_t planted : {ref.size() - 1, std::size_t{0}}) {
    std::vector<Vec3> moved = ref;
    moved[planted].y() += 3e-6;
    const auto d = on_threads<double>([&] { return max_displacement(moved, ref, c.box); });
    const auto d_na = on_threads<double>([&] { return max_nonaffine_displacement(moved, ref, c.box, 0.0); });
    EXPECT_NEAR(d[0], 3e-6, 1e-12) << "planted at " << planted;
    for (int t = 1; t < k_runs; ++t) {
      EXPECT_EQ(d[0], d[t]) << "run " << t;
      EXPECT_EQ(d[0], d_na[t]) << "run " << t;
    }
  }
}

}  // namespace
}  // namespace mrf
