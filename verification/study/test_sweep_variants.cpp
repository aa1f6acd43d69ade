// Sweep variants: the grid run once per named set of overrides (a
// convergence study in one numerical choice, the conditions of a held-out
// design), each variant with its own folder level and, optionally, its own
// Mason numbers; sweep.csv and the criterion keep the variants apart.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mrf/error.hpp"
#include "mrf/study/criterion.hpp"
#include "mrf/study/sweep.hpp"

namespace mrf {
namespace {

const std::string k_scenes = MRF_SOURCE_DIR "/experiments/scenes";

std::string text(const std::string& sweep_mason, const std::string& variants) {
  return "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\", \"demsph_dd\"]\n" + sweep_mason +
         "seeds = [1, 2]\nset = [\"drive.strain=4\"]\n"
         "[[rule]]\nmason_max = 2e-3\nset = [\"drive.strain=2\"]\n" +
         variants;
}

const std::string k_two = "[[variant]]\nname = \"base\"\n"
                          "[[variant]]\nname = \"stiff\"\nset = [\"contact.youngs_modulus=2e12\", \"drive.strain=3\"]\n"
                          "mason = [0.5]\n";

TEST(SweepVariants, GridIsModelVariantMasonSeedWithTheVariantAfterTheRules) {
  const auto pts = sweep_points(parse_sweep(text("mason = [1e-3, 0.01]\n", k_two), "v.toml", k_scenes));
  // per model: base x 2 Mn x 2 seeds + stiff x 1 Mn x 2 seeds
  ASSERT_EQ(pts.size(), 2u * (4u + 2u));
  EXPECT_EQ(pts[0].variant, "base");
  EXPECT_EQ(pts[0].dir, "dem_stokes/base/mn_0.001_seed_1");
  EXPECT_EQ(pts[4].variant, "stiff");
  EXPECT_EQ(pts[4].mason, 0.5);
  EXPECT_EQ(pts[4].dir, "dem_stokes/stiff/mn_0.5_seed_1");
  EXPECT_EQ(pts[6].model, "demsph_dd");
  EXPECT_EQ(pts[6].dir, "demsph_dd/base/mn_0.001_seed_1");
  // sweep set, rules, variant set, then the point's own keys: the variant's strain wins over the sweep's
  const std::vector<std::string> stiff{"drive.strain=4", "contact.youngs_modulus=2e12", "drive.strain=3",
                                       "scene.model=\"dem_stokes\"", "drive.mason=0.5", "scene.seed=1"};
  EXPECT_EQ(pts[4].sets, stiff);
  const std::vector<std::string> base{"drive.strain=4", "drive.strain=2", "scene.model=\"dem_stokes\"",
                                      "drive.mason=0.001", "scene.seed=1"};
  EXPECT_EQ(pts[0].sets, base);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(pts[i].index, i);
  // a variant for some models only
  const auto some = sweep_points(parse_sweep(
      text("mason = [0.01]\n", "[[variant]]\nname = \"b\"\n[[variant]]\nname = \"sph\"\nmodels = [\"demsph_dd\"]\n"),
      "v.toml", k_scenes));
  ASSERT_EQ(some.size(), 2u + 4u);  // dem_stokes: b x 2 seeds; demsph_dd: (b + sph) x 2 seeds
  EXPECT_EQ(some[1].dir, "dem_stokes/b/mn_0.01_seed_2");
  EXPECT_EQ(some[4].dir, "demsph_dd/sph/mn_0.01_seed_1");
  // without variants nothing changes: no folder level, empty variant
  const auto plain = sweep_points(parse_sweep(text("mason = [1e-3, 0.01]\n", ""), "v.toml", k_scenes));
  ASSERT_EQ(plain.size(), 8u);
  EXPECT_EQ(plain[0].dir, "dem_stokes/mn_0.001_seed_1");
  EXPECT_TRUE(plain[0].variant.empty());
}

TEST(SweepRules, SeedsSelectThePointsARuleLengthens) {
  // a rule for seed 2 alone (a re-run of a point that failed a steadiness
  // test): the other seed keeps its overrides, so its scene and archive
  // entry are unchanged
  const std::string t = text("mason = [0.01]\n", "[[rule]]\nmodels = [\"demsph_dd\"]\nseeds = [2]\n"
                                                  "set = [\"drive.strain=8\"]\n");
  const auto pts = sweep_points(parse_sweep(t, "v.toml", k_scenes));
  ASSERT_EQ(pts.size(), 4u);
  const std::vector<std::string> plain{"drive.strain=4", "scene.model=\"demsph_dd\"", "drive.mason=0.01", "scene.seed=1"};
  const std::vector<std::string> longer{"drive.strain=4", "drive.strain=8", "scene.model=\"demsph_dd\"",
                                        "drive.mason=0.01", "scene.seed=2"};
  EXPECT_EQ(pts[2].sets, plain);
  EXPECT_EQ(pts[3].sets, longer);
  EXPECT_EQ(pts[1].sets.size(), 4u);  // dem_stokes seed 2: not the rule's model
  for (const std::string bad : {"seeds = [-1]\n", "seeds = [\"2\"]\n", "seeds = 2\n"}) {
    try {
      parse_sweep(text("mason = [0.01]\n", "[[rule]]\n" + bad + "set = [\"drive.strain=8\"]\n"), "v.toml", k_scenes);
      FAIL() << "expected InputError for " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "rule.seeds") << e.what();
      EXPECT_NE(std::string(e.what()).find("v.toml:11"), std::string::npos) << e.what();
    }
  }
}

// A sweep.set that is not an array is an error (it was dropped, and every
// point ran the base scene's strain); two grid points that would share one
// folder (a repeated seed, Mn equal to 4 digits) are an error naming it.
TEST(SweepSpecErrors, SetNotAnArrayAndSharedFoldersAreRefused) {
  const std::string head = "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\n";
  const std::vector<std::pair<std::string, std::string>> bad{
      {"mason = [0.01]\nseeds = [1]\nset = \"drive.strain=0.2\"\n", "sweep.set"},
      {"mason = [0.01]\nseeds = [1, 2, 1]\n", "sweep"},
      {"mason = [0.30001, 0.30002]\nseeds = [1]\n", "sweep"}};
  for (const auto& [body, key] : bad) {
    try {
      parse_sweep(head + body, "e.toml", k_scenes);
      ADD_FAILURE() << "expected InputError for " << body;
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  }
  EXPECT_NO_THROW(parse_sweep(head + "mason = [0.3, 0.3002]\nseeds = [1, 2]\nset = [\"drive.strain=0.2\"]\n",
                              "e.toml", k_scenes));
}

TEST(SweepRules, ARuleNamingVariantsRefinesThemAfterTheirOwnOverrides) {
  // a longer run of the "stiff" variant alone, at its Mn and for seed 2 (a
  // convergence variant that failed a steadiness test): its strain wins over
  // the variant's own, and every other point keeps its overrides
  const std::string t = text("mason = [0.01]\n", k_two + "[[rule]]\nvariants = [\"stiff\"]\nmodels = [\"dem_stokes\"]\n"
                                                      "seeds = [2]\nset = [\"drive.strain=6\"]\n");
  const auto pts = sweep_points(parse_sweep(t, "v.toml", k_scenes));
  const auto plain = sweep_points(parse_sweep(text("mason = [0.01]\n", k_two), "v.toml", k_scenes));
  ASSERT_EQ(pts.size(), plain.size());
  int refined = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].variant == "stiff" && pts[i].model == "dem_stokes" && pts[i].seed == 2) {
      const std::vector<std::string> want{"drive.strain=4", "contact.youngs_modulus=2e12", "drive.strain=3",
                                          "drive.strain=6", "scene.model=\"dem_stokes\"", "drive.mason=0.5",
                                          "scene.seed=2"};
      EXPECT_EQ(pts[i].sets, want);
      ++refined;
    } else {
      EXPECT_EQ(pts[i].sets, plain[i].sets) << pts[i].dir;
    }
  }
  EXPECT_EQ(refined, 1);
  try {
    parse_sweep(text("mason = [0.01]\n", k_two + "[[rule]]\nvariants = [\"soft\"]\nset = [\"drive.strain=6\"]\n"),
                "v.toml", k_scenes);
    FAIL() << "a rule naming no variant of the sweep must be refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "rule.variants") << e.what();
    EXPECT_NE(std::string(e.what()).find("soft"), std::string::npos) << e.what();
  }
}

TEST(SweepVariants, SweepMasonMayBeLeftOutOnlyWhenEveryVariantHasItsOwn) {
  const std::string own = "[[variant]]\nname = \"a\"\nmason = [0.1]\n[[variant]]\nname = \"b\"\nmason = [0.2, 0.3]\n";
  EXPECT_EQ(sweep_points(parse_sweep(text("", own), "v.toml", k_scenes)).size(), 2u * 3u * 2u);
  auto expect_error = [](const std::string& t, const std::string& key, const std::string& where) {
    try {
      parse_sweep(t, "v.toml", k_scenes);
      FAIL() << "expected InputError for " << key;
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  };
  expect_error(text("", "[[variant]]\nname = \"a\"\n"), "variant.mason", "v.toml:9");
  expect_error(text("mason = [1]\n", "[[variant]]\nname = \"../up\"\n"), "variant.name", "v.toml:11");
  expect_error(text("mason = [1]\n", "[[variant]]\nset = [\"a.b=1\"]\n"), "variant.name", "v.toml:10");
  expect_error(text("mason = [1]\n", "[[variant]]\nname = \"a\"\n[[variant]]\nname = \"a\"\n"), "variant.name",
               "v.toml:12");
  expect_error(text("mason = [1]\n", "[[variant]]\nname = \"a\"\nspeed = 2\n"), "variant.speed", "v.toml:12");
  expect_error(text("mason = [1]\n", "[[variant]]\nname = \"a\"\nmason = [-1]\n"), "variant.mason", "v.toml:12");
  expect_error(text("mason = [1]\n", "[[variant]]\nname = \"a\"\nmodels = [\"demsph_stokes\"]\n"), "variant.models",
               "v.toml:12");
}

// sweep.csv carries the variant, and the criterion reads one flow curve per
// model and variant ("model@variant"), never mixing two variants' points.
TEST(SweepVariants, SweepCsvAndCriterionKeepTheVariantsApart) {
  const auto out = std::filesystem::temp_directory_path() / "mrf_test_sweep_variants";
  std::filesystem::remove_all(out);
  const auto pts = sweep_points(parse_sweep(text("mason = [1e-3, 0.01]\n", k_two), "v.toml", k_scenes));
  for (const auto& p : pts) {
    std::filesystem::create_directories(out / p.dir);
    nlohmann::json j{{"stress_total", p.variant == "stiff" ? 2.0 : 1.0}, {"stress_total_err", 0.1},
                     {"stress_fluid", 0.5}, {"magnetization", 1e6}, {"volume_fraction", 0.3},
                     {"viscosity", 0.1}, {"shear_rate", 10.0}};
    std::ofstream(out / p.dir / "summary.json") << j.dump();
  }
  std::ofstream(out / "sweep.csv") << sweep_csv(pts, out.string());
  const SweepTable t = read_sweep_csv((out / "sweep.csv").string());
  ASSERT_EQ(t.samples.size(), 4u);
  EXPECT_EQ(t.samples.at("dem_stokes@base").size(), 4u);
  ASSERT_EQ(t.samples.at("demsph_dd@stiff").size(), 2u);
  for (const auto& s : t.samples.at("demsph_dd@stiff")) EXPECT_EQ(s.stress, 2.0);
  for (const auto& s : t.samples.at("dem_stokes@base")) EXPECT_EQ(s.stress, 1.0);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace mrf
