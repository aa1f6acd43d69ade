// The lists a long implicit run of model 1 relies on hold every pair they
// must, step after step, on the paper cell at Mn = 0.1 on the realistic path
// (the point whose value moved with the Verlet skin, session 30): after each
// accepted step, against a fresh search at the new positions,
//   - the free-free Verlet list holds every pair within its range,
//   - the free-wall list every free-wall pair within contact range + margin,
//   - the step's contact candidates (built at the start of the step from the
//     near list) every pair within 2R + margin at the start of the step and
//     every pair in contact (closer than 2R) at its end.
// A pair missing from any of them would be a force left out (or a contact
// left to the explicit part); the test fails at the first step that misses
// one and names it. Run with the adaptive skin and with the largest fixed
// skin the box allows (2R), the two runs whose stresses differed. Can fail:
// with the rebuild bound's non-affine term dropped (only the imposed strain
// counted), the adaptive run misses a candidate pair at step 1030.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "mrf/integrate/stability.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/neighbors/cell_list.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {
namespace {

constexpr int k_steps = 1500;

struct Missing {
  std::size_t count = 0;
  std::string first;
  void see(const char* what, std::uint32_t i, std::uint32_t k) {
    if (count++ == 0) first = std::string(what) + " (" + std::to_string(i) + ", " + std::to_string(k) + ")";
  }
};

// Pairs of `want` not in `have` (both as (i, k); have need not be sorted).
void missing_from(const std::vector<IndexPair>& want, std::vector<IndexPair> have, const char* what, Missing& m) {
  std::sort(have.begin(), have.end());
  for (const IndexPair& p : want)
    if (!std::binary_search(have.begin(), have.end(), p)) m.see(what, p.first, p.second);
}

std::vector<IndexPair> rows_as_pairs(const PairRows& rows) {
  std::vector<IndexPair> out;
  for (std::size_t i = 0; i < rows.rows(); ++i)
    for (std::uint32_t n = rows.start[i]; n < rows.start[i + 1]; ++n)
      out.emplace_back(static_cast<std::uint32_t>(i), rows.k[n]);
  return out;
}

void split(const std::vector<ContactPair>& pairs, std::vector<IndexPair>& ff, std::vector<IndexPair>& fw) {
  ff.clear();
  fw.clear();
  for (const ContactPair& p : pairs) (p.wall ? fw : ff).emplace_back(p.i, p.k);
}

struct Tally {
  std::size_t steps = 0, contacts = 0, candidates = 0, ff_builds = 0;
  double strain = 0;
};

Tally check_run(const std::vector<std::string>& overrides) {
  const LoadedScene sc = load_scene(MRF_SOURCE_DIR "/experiments/scenes/paper_dem_stokes.toml", overrides);
  BuiltModel built = build_model(sc);
  auto* model = dynamic_cast<DemModel*>(built.model.get());
  EXPECT_NE(model, nullptr);
  EXPECT_NE(model->implicit(), nullptr) << "auto should choose the implicit scheme on the realistic path";
  if (model == nullptr || model->implicit() == nullptr) return {};
  const double r = model->params().radius, reach = 2.0 * r + k_contact_margin_over_radius * r;
  Tally t;
  std::vector<IndexPair> cand_ff, cand_fw;
  for (int n = 0; n < k_steps; ++n) {
    const ShearCell& c = model->cell();
    const std::vector<Vec3> x0 = c.free.x, w0 = c.walls.x;
    model->step();
    const DemPairLists& l = model->lists();
    Missing m;
    PairRows fresh;
    self_pair_rows(c.free.x, c.box, l.ff_range, fresh);
    missing_from(rows_as_pairs(fresh), rows_as_pairs(l.ff), "free-free list", m);
    missing_from(cross_pairs(c.free.x, c.walls.x, c.box, l.fw_range), l.fw, "free-wall list", m);
    split(model->implicit()->candidates(), cand_ff, cand_fw);
    missing_from(self_pairs(x0, c.box, reach), cand_ff, "candidates at the start, free-free", m);
    missing_from(cross_pairs(x0, w0, c.box, reach), cand_fw, "candidates at the start, free-wall", m);
    const std::vector<IndexPair> touching = self_pairs(c.free.x, c.box, 2.0 * r);
    const std::vector<IndexPair> touching_walls = cross_pairs(c.free.x, c.walls.x, c.box, 2.0 * r);
    missing_from(touching, cand_ff, "contact at the end, free-free", m);
    missing_from(touching_walls, cand_fw, "contact at the end, free-wall", m);
    if (m.count > 0) {
      ADD_FAILURE() << m.count << " pairs missing after step " << n << " (t = " << model->time()
                    << " s), first: " << m.first;
      break;
    }
    t.contacts += touching.size() + touching_walls.size();
    t.candidates += cand_ff.size() + cand_fw.size();
    ++t.steps;
  }
  t.ff_builds = static_cast<std::size_t>(model->lists().ff_builds);
  t.strain = model->params().shear_rate * model->time();
  const double per_step = 1.0 / static_cast<double>(std::max<std::size_t>(t.steps, 1));
  std::printf("%zu steps checked, strain %.2f: %zu free-free builds, skin %.2f R, mean contacts %.0f, "
              "candidates %.0f\n",
              t.steps, t.strain, t.ff_builds, model->lists().skin / r, static_cast<double>(t.contacts) * per_step,
              static_cast<double>(t.candidates) * per_step);
  return t;
}

const std::vector<std::string> k_realistic_mn_0p1 = {"numerics.threads=1", "drive.vary='magnetization'",
                                                     "drive.shear_rate=1e3", "drive.mason=0.1",
                                                     "drive.strain=400", "drive.warmup_strain=200"};

TEST(ListCompletenessSlow, PaperCellAdaptiveSkinKeepsEveryPairAndContact) {
  const Tally t = check_run(k_realistic_mn_0p1);
  // the check had something to check: contacts, rebuilds, strain
  EXPECT_GT(t.contacts, std::size_t{1000} * k_steps);
  EXPECT_GT(t.ff_builds, 10u);
  EXPECT_GT(t.strain, 5.0);
}

TEST(ListCompletenessSlow, PaperCellLargestSkinKeepsEveryPairAndContact) {
  std::vector<std::string> o = k_realistic_mn_0p1;
  o.push_back("numerics.skin='5 um'");
  const Tally t = check_run(o);
  EXPECT_GT(t.contacts, std::size_t{1000} * k_steps);
  EXPECT_GT(t.strain, 5.0);
}

}  // namespace
}  // namespace mrf
