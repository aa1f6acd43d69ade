// The sweep archive (`mrf sweep --archive DIR`): finished points survive the
// loss of the sweep output, and an entry of an edited scene is never used.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/study/sweep.hpp"

namespace mrf {
namespace {

const std::string k_scenes = MRF_SOURCE_DIR "/experiments/scenes";

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

SweepSpec tiny(const std::string& strain) {
  return parse_sweep("[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [0.3, 1.0]\n"
                     "seeds = [5]\nset = [\"drive.strain=" + strain + "\", \"drive.warmup_strain=0.2\"]\n",
                     "tiny.toml", k_scenes);
}

TEST(SweepArchive, SceneIdChangesWithEveryParameterAndOnlyThen) {
  const std::string path = k_scenes + "/small_dem_stokes.toml";
  const std::string base = scene_id(load_scene(path).config);
  EXPECT_EQ(base.size(), 8u);
  EXPECT_EQ(scene_id(load_scene(path).config), base);
  for (const char* set : {"scene.seed=99", "drive.strain=7", "particles.magnetization=2e5", "fluid.viscosity=0.2",
                          "contact.youngs_modulus=3e10", "numerics.newton_tol=1e-7"})
    EXPECT_NE(scene_id(load_scene(path, {set}).config), base) << set;
  // numerics.newton_tol came after points were archived: at its default it
  // leaves the scene_id of every earlier scene as it was
  EXPECT_EQ(scene_id(load_scene(path, {"numerics.newton_tol=1e-6"}).config), base);
}

TEST(SweepArchive, FinishedPointsSurviveTheLossOfTheOutputAndStaleEntriesRunAgain) {
  const auto root = std::filesystem::temp_directory_path() / "mrf_test_sweep_archive";
  std::filesystem::remove_all(root);
  const auto archive = root / "archive";
  SweepOptions opt;
  opt.quiet = true;
  opt.archive = archive.string();

  // The first working period: both points run and are archived.
  const SweepSpec s = tiny("0.6");
  const SweepOutcome first = run_sweep(s, (root / "out1").string(), opt);
  ASSERT_EQ(first.ran, 2u);
  const auto pts = sweep_points(s);
  for (const auto& p : pts)
    EXPECT_EQ(slurp(archive / p.dir / "summary.json"), slurp(root / "out1" / p.dir / "summary.json")) << p.dir;

  // A new machine: the output is gone, the archive is not. Nothing runs, the
  // summaries come back byte for byte, sweep.csv is complete.
  const SweepOutcome second = run_sweep(s, (root / "out2").string(), opt);
  EXPECT_EQ(second.ran, 0u);
  EXPECT_EQ(second.skipped, 2u);
  for (const auto& p : pts)
    EXPECT_EQ(slurp(root / "out2" / p.dir / "summary.json"), slurp(root / "out1" / p.dir / "summary.json"));
  EXPECT_EQ(slurp(root / "out2" / "sweep.csv"), slurp(root / "out1" / "sweep.csv"));

  // An unreadable entry is stale: the point runs again (and reproduces).
  const std::string good = slurp(archive / pts[0].dir / "summary.json");
  std::ofstream(archive / pts[0].dir / "summary.json") << "{ \"half";
  const ArchiveSync broken = restore_from_archive(s, pts, (root / "out3").string(), archive.string());
  EXPECT_EQ(broken.restored, 1u);
  ASSERT_EQ(broken.stale.size(), 1u);
  EXPECT_EQ(broken.stale[0], pts[0].dir);
  const SweepOutcome third = run_sweep(s, (root / "out3").string(), opt);
  EXPECT_EQ(third.ran, 1u);
  nlohmann::json a = nlohmann::json::parse(slurp(archive / pts[0].dir / "summary.json"));
  nlohmann::json b = nlohmann::json::parse(good);
  EXPECT_EQ(a["stress_total"], b["stress_total"]);  // deterministic: the rerun equals the lost entry

  // The sweep file is edited (a longer strain): every entry is for another
  // scene, so every point runs, and the archive then holds the new results.
  const SweepSpec edited = tiny("0.8");
  const ArchiveSync sync = restore_from_archive(edited, sweep_points(edited), (root / "out4").string(), archive.string());
  EXPECT_EQ(sync.restored, 0u);
  EXPECT_EQ(sync.stale.size(), 2u);
  const SweepOutcome fourth = run_sweep(edited, (root / "out4").string(), opt);
  EXPECT_EQ(fourth.ran, 2u);
  const std::string want = scene_id(load_scene(edited.scene_path, sweep_points(edited)[1].sets).config);
  EXPECT_EQ(nlohmann::json::parse(slurp(archive / pts[1].dir / "summary.json"))["scene_id"], want);
  EXPECT_EQ(nlohmann::json::parse(slurp(archive / pts[1].dir / "summary.json"))["strain"], 0.8);
  std::filesystem::remove_all(root);
}

// The same rule for the output folder (no archive): after an edit of the
// sweep file, a finished point's folder holds a run of another scene; the
// sweep moves it to <folder>.stale and runs the point again, and --collect
// never lists the old run as the point's.
TEST(SweepArchive, AFinishedRunOfAnotherSceneInTheOutputRunsAgain) {
  const auto root = std::filesystem::temp_directory_path() / "mrf_test_sweep_stale_output";
  std::filesystem::remove_all(root);
  const std::string out = (root / "out").string();
  SweepOptions opt;
  opt.quiet = true;
  const SweepSpec s = tiny("0.6");
  ASSERT_EQ(run_sweep(s, out, opt).ran, 2u);
  EXPECT_EQ(run_sweep(s, out, opt).ran, 0u);  // unchanged: nothing runs, nothing moves
  const auto pts = sweep_points(s);
  EXPECT_FALSE(std::filesystem::exists(root / "out" / (pts[0].dir + ".stale")));
  const std::string old0 = slurp(root / "out" / pts[0].dir / "summary.json");

  const SweepSpec edited = tiny("0.8");
  const auto moved = set_aside_stale(edited, sweep_points(edited), out, true);  // what --collect does first
  EXPECT_EQ(moved.size(), 2u);
  EXPECT_EQ(slurp(root / "out" / (pts[0].dir + ".stale") / "summary.json"), old0);
  EXPECT_EQ(write_sweep_csv(sweep_points(edited), out), 0u);  // no point of the edited sweep is finished
  const SweepOutcome again = run_sweep(edited, out, opt);
  EXPECT_EQ(again.ran, 2u);
  EXPECT_EQ(nlohmann::json::parse(slurp(root / "out" / pts[0].dir / "summary.json"))["strain"], 0.8);
  EXPECT_TRUE(set_aside_stale(edited, sweep_points(edited), out, true).empty());

  // An unfinished run (a checkpoint, no summary) of the old scene: resuming
  // it would be refused, so it is set aside too; one of the current scene is
  // left to resume.
  const auto pe = sweep_points(edited);
  std::filesystem::remove_all(root / "out" / pe[0].dir);
  RunOptions cut;
  cut.out_dir = (root / "out" / pe[0].dir).string();
  cut.quiet = true;
  cut.checkpoint_every_rows = 5;
  cut.stop_after_steps = 40;
  EXPECT_THROW(run_scene(load_scene(s.scene_path, sweep_points(s)[0].sets), cut), RunInterrupted);  // the old scene
  ASSERT_TRUE(std::filesystem::exists(root / "out" / pe[0].dir / "checkpoint.bin"));
  EXPECT_EQ(set_aside_stale(edited, pe, out, true), std::vector<std::string>{pe[0].dir});
  EXPECT_THROW(run_scene(load_scene(edited.scene_path, pe[0].sets), cut), RunInterrupted);  // the current one
  ASSERT_TRUE(std::filesystem::exists(root / "out" / pe[0].dir / "checkpoint.bin"));
  EXPECT_TRUE(set_aside_stale(edited, pe, out, true).empty());
  std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace mrf
