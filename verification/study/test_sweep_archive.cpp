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
#include "mrf/io/timeseries.hpp"
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

// A run into `dir` stopped after 40 steps, with checkpoints (a point under way).
RunOptions cut_after_40_steps(const std::filesystem::path& dir) {
  RunOptions cut;
  cut.out_dir = dir.string();
  cut.quiet = true;
  cut.checkpoint_every_rows = 5;
  cut.stop_after_steps = 40;
  return cut;
}

TEST(SweepArchive, SceneIdChangesWithEveryParameterAndOnlyThen) {
  const std::string path = k_scenes + "/small_dem_stokes.toml";
  const std::string base = scene_id(load_scene(path).config);
  EXPECT_EQ(base.size(), 8u);
  EXPECT_EQ(scene_id(load_scene(path).config), base);
  for (const char* set : {"scene.seed=99", "drive.strain=7", "particles.magnetization=2e5", "fluid.viscosity=0.2",
                          "contact.youngs_modulus=3e10", "numerics.newton_tol=1e-7"})
    EXPECT_NE(scene_id(load_scene(path, {set}).config), base) << set;
  // numerics.newton_tol and fluid.eos_reference came after points were
  // archived: at the value every scene had before (newton_tol's default;
  // eos_reference "start", the default until session 37) they leave the
  // scene_id of every earlier scene as it was
  EXPECT_EQ(scene_id(load_scene(path, {"numerics.newton_tol=1e-6"}).config), base);
  const std::string coupled = k_scenes + "/small_demsph_dd.toml";
  const std::string start = scene_id(load_scene(coupled, {"fluid.eos_reference=\"start\""}).config);
  EXPECT_NE(scene_id(load_scene(coupled).config), start);  // the default now: common
  EXPECT_EQ(scene_id(load_scene(coupled, {"fluid.eos_reference=\"common\""}).config),
            scene_id(load_scene(coupled).config));
  // nor does a two-way scene without spheres (the fluid alone: every
  // particle has the fluid density as its reference either way)
  EXPECT_EQ(scene_id(load_scene(coupled, {"particles.volume_fraction=0", "fluid.eos_reference=\"start\""}).config),
            scene_id(load_scene(coupled, {"particles.volume_fraction=0"}).config));
  // model 1 has no carrier: the key leaves its scene_id alone
  EXPECT_EQ(scene_id(load_scene(path, {"fluid.eos_reference=\"start\""}).config), base);
  EXPECT_EQ(scene_id(load_scene(path, {"fluid.eos_reference=\"common\""}).config), base);
}

// The committed archive of the paper study still matches the scenes its
// sweep file defines: a change of the scene fingerprint (a new scene key
// entered at its default, say) would make every committed point stale and
// run again. Every entry is checked but those whose re-run for steadiness
// (another strain, by a rule of the sweep file) is still pending.
TEST(SweepArchive, TheCommittedPaperArchiveMatchesItsSweepFile) {
  const SweepSpec paper = load_sweep(MRF_SOURCE_DIR "/experiments/sweeps/paper_realistic.toml");
  int checked = 0;
  for (const SweepPoint& p : sweep_points(paper)) {
    const auto entry = std::filesystem::path(MRF_SOURCE_DIR "/reports/study/paper/points") / p.dir / "summary.json";
    ASSERT_TRUE(std::filesystem::exists(entry)) << entry;
    const nlohmann::json j = nlohmann::json::parse(slurp(entry));
    const SceneConfig c = load_scene(paper.scene_path, p.sets).config;
    if (j["strain"].get<double>() != c.strain) continue;  // a re-run pending: the entry is its first run
    EXPECT_EQ(j["scene_id"].get<std::string>(), scene_id(c)) << p.dir;
    ++checked;
  }
  EXPECT_GE(checked, 30);
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
  for (const auto& p : pts) {
    EXPECT_EQ(slurp(archive / p.dir / "summary.json"), slurp(root / "out1" / p.dir / "summary.json")) << p.dir;
    // and the averaging window's series, for a later re-analysis
    EXPECT_NE(slurp(archive / p.dir / k_window_series_file).find("stress_total_Pa"), std::string::npos) << p.dir;
  }

  // An entry archived before the window series existed gets it back from
  // the run in the output whose summary it holds (and only from that run).
  std::filesystem::remove(archive / pts[0].dir / k_window_series_file);
  const ArchiveSync backfill = restore_from_archive(s, pts, (root / "out1").string(), archive.string());
  EXPECT_EQ(backfill.series_added, 1u);
  EXPECT_EQ(backfill.restored, 0u);
  EXPECT_TRUE(std::filesystem::exists(archive / pts[0].dir / k_window_series_file));
  const auto other = root / "other";  // a finished run whose summary is not the entry's
  std::filesystem::copy(root / "out1", other, std::filesystem::copy_options::recursive);
  std::ofstream(other / pts[1].dir / "summary.json", std::ios::app) << " ";
  std::filesystem::remove(archive / pts[1].dir / k_window_series_file);
  EXPECT_EQ(restore_from_archive(s, pts, other.string(), archive.string()).series_added, 0u);
  EXPECT_FALSE(std::filesystem::exists(archive / pts[1].dir / k_window_series_file));
  EXPECT_EQ(restore_from_archive(s, pts, (root / "out1").string(), archive.string()).series_added, 1u);

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

// What an interruption can leave behind. A damaged record (a summary.json
// that does not read, as a crash just after its write may leave) does not
// count as finished: the sweep runs the point again. A point that finished
// in the output but never reached the archive (the sweep killed between the
// two) is archived by the next sweep. Restoring an entry over a partial run
// removes that run's series, which would otherwise pass for the entry's.
TEST(SweepArchive, InterruptionsLeaveNoDamagedOrMissingRecord) {
  const auto root = std::filesystem::temp_directory_path() / "mrf_test_sweep_interrupted";
  std::filesystem::remove_all(root);
  const auto archive = root / "archive";
  const std::string out = (root / "out").string();
  SweepOptions opt;
  opt.quiet = true;
  opt.archive = archive.string();
  const SweepSpec s = tiny("0.6");
  const auto pts = sweep_points(s);
  ASSERT_EQ(run_sweep(s, out, opt).ran, 2u);
  const std::string good = slurp(root / "out" / pts[0].dir / "summary.json");

  std::ofstream(root / "out" / pts[0].dir / "summary.json", std::ios::trunc) << "";  // the crash's empty file
  EXPECT_FALSE(point_finished((root / "out" / pts[0].dir).string()));
  EXPECT_TRUE(point_record_damaged((root / "out" / pts[0].dir).string()));
  SweepOptions plain = opt;
  plain.archive.clear();  // the archive would restore it; without one the point runs
  EXPECT_EQ(run_sweep(s, out, plain).ran, 1u);
  EXPECT_FALSE(point_record_damaged((root / "out" / pts[0].dir).string()));
  EXPECT_EQ(nlohmann::json::parse(slurp(root / "out" / pts[0].dir / "summary.json"))["stress_total"],
            nlohmann::json::parse(good)["stress_total"]);

  // a finished point missing from the archive (and one whose entry is
  // damaged) is archived from the output
  std::filesystem::remove_all(archive / pts[1].dir);
  std::ofstream(archive / pts[0].dir / "summary.json", std::ios::trunc) << "{";
  const ArchiveSync late = restore_from_archive(s, pts, out, archive.string());
  EXPECT_EQ(late.archived, 2u);
  EXPECT_EQ(late.restored, 0u);
  for (const auto& p : pts)
    EXPECT_EQ(slurp(archive / p.dir / "summary.json"), slurp(root / "out" / p.dir / "summary.json")) << p.dir;
  EXPECT_EQ(restore_from_archive(s, pts, out, archive.string()).archived, 0u);

  // an entry restored over a partial run of the point: the run's checkpoint
  // and series go, the entry's summary stays
  std::filesystem::remove_all(root / "out" / pts[1].dir);
  EXPECT_THROW(run_scene(load_scene(s.scene_path, pts[1].sets), cut_after_40_steps(root / "out" / pts[1].dir)),
               RunInterrupted);
  ASSERT_TRUE(std::filesystem::exists(root / "out" / pts[1].dir / "timeseries.csv"));
  EXPECT_EQ(restore_from_archive(s, pts, out, archive.string()).restored, 1u);
  EXPECT_EQ(slurp(root / "out" / pts[1].dir / "summary.json"), slurp(archive / pts[1].dir / "summary.json"));
  EXPECT_FALSE(std::filesystem::exists(root / "out" / pts[1].dir / "checkpoint.bin"));
  EXPECT_FALSE(std::filesystem::exists(root / "out" / pts[1].dir / "timeseries.csv"));
  std::filesystem::remove_all(root);
}

// The same rule for the output folder (no archive): after an edit of the
// sweep file a finished point's folder holds a run of another scene. A
// read-only collect lists it as stale (and moves nothing); the sweep moves
// it to <folder>.stale-<its scene_id> and runs the point again; reverting
// the edit brings the first runs back instead of running them again.
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
  const std::string id_s = scene_id(load_scene(s.scene_path, pts[0].sets).config);
  EXPECT_EQ(folder_scene_id(root / "out" / pts[0].dir), id_s);
  const std::string old0 = slurp(root / "out" / pts[0].dir / "summary.json");

  const SweepSpec edited = tiny("0.8");
  const auto pe = sweep_points(edited);
  EXPECT_EQ(write_sweep_csv(pe, out, &edited), 0u);  // what --collect does: nothing finished, nothing moved
  EXPECT_NE(slurp(root / "out" / "sweep.csv").find(",stale,"), std::string::npos);
  EXPECT_EQ(slurp(root / "out" / pts[0].dir / "summary.json"), old0);
  const SweepOutcome again = run_sweep(edited, out, opt);
  EXPECT_EQ(again.ran, 2u);
  EXPECT_EQ(slurp(root / "out" / (pts[0].dir + ".stale-" + id_s) / "summary.json"), old0);
  EXPECT_EQ(nlohmann::json::parse(slurp(root / "out" / pts[0].dir / "summary.json"))["strain"], 0.8);
  EXPECT_EQ(write_sweep_csv(pe, out, &edited), 2u);
  EXPECT_TRUE(set_aside_stale(edited, pe, out, true).empty());

  // The edit reverted: the 0.8 runs go aside, the 0.6 runs come back.
  EXPECT_EQ(set_aside_stale(s, pts, out, true).size(), 2u);
  EXPECT_EQ(slurp(root / "out" / pts[0].dir / "summary.json"), old0);
  EXPECT_EQ(run_sweep(s, out, opt).ran, 0u);

  // A failure of another scene (failure.json carries the scene_id) is moved
  // too; an unfinished run (a checkpoint, no summary) of another scene as
  // well, whose resume would be refused; one of the current scene stays.
  std::filesystem::remove_all(root / "out" / pe[1].dir);
  std::filesystem::create_directories(root / "out" / pe[1].dir);
  std::ofstream(root / "out" / pe[1].dir / "failure.json") << "{\"scene_id\": \"" << id_s << "\"}";
  std::filesystem::remove_all(root / "out" / pe[0].dir);
  const RunOptions cut = cut_after_40_steps(root / "out" / pe[0].dir);
  EXPECT_THROW(run_scene(load_scene(s.scene_path, pts[0].sets), cut), RunInterrupted);  // the old scene
  ASSERT_TRUE(std::filesystem::exists(root / "out" / pe[0].dir / "checkpoint.bin"));
  EXPECT_EQ(folder_scene_id(root / "out" / pe[0].dir), id_s);
  EXPECT_EQ(set_aside_stale(edited, pe, out, true), (std::vector<std::string>{pe[0].dir, pe[1].dir}));
  EXPECT_TRUE(std::filesystem::exists(root / "out" / pe[0].dir / "summary.json"));  // the 0.8 run came back
  std::filesystem::remove_all(root / "out" / pe[0].dir);
  EXPECT_THROW(run_scene(load_scene(edited.scene_path, pe[0].sets), cut), RunInterrupted);  // the current one
  ASSERT_TRUE(std::filesystem::exists(root / "out" / pe[0].dir / "checkpoint.bin"));
  EXPECT_TRUE(set_aside_stale(edited, {pe[0]}, out, true).empty());
  std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace mrf
