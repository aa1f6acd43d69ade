// Checkpoint and resume (issue 6): a run killed after a checkpoint and
// resumed ends bit for bit as the uninterrupted run; a checkpoint never
// resumes into a different scene.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

const std::string k_scene = MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml";

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

LoadedScene scene(const std::string& integrator, double mason = 1.0, int frames = 5) {
  return load_scene(k_scene, {"drive.mason=" + std::to_string(mason), "drive.strain=0.5", "drive.warmup_strain=0.1",
                              "numerics.integrator=\"" + integrator + "\"", "output.frames=" + std::to_string(frames)});
}

void check_resume_reproduces(const std::string& integrator) {
  const auto base = std::filesystem::temp_directory_path() / ("mrf_ckpt_" + integrator);
  std::filesystem::remove_all(base);
  RunOptions whole;
  whole.out_dir = (base / "whole").string();
  whole.quiet = true;
  whole.checkpoint_seconds = 0;
  const RunSummary a = run_scene(scene(integrator), whole);

  RunOptions cut = whole;
  cut.out_dir = (base / "cut").string();
  cut.checkpoint_every_rows = 20;
  cut.stop_after_steps = a.steps * 2 / 3;
  EXPECT_THROW(run_scene(scene(integrator), cut), RunInterrupted);
  ASSERT_TRUE(std::filesystem::exists(base / "cut/checkpoint.bin"));
  EXPECT_FALSE(std::filesystem::exists(base / "cut/summary.json"));

  cut.stop_after_steps = 0;
  cut.resume = true;
  const RunSummary b = run_scene(scene(integrator), cut);
  EXPECT_EQ(b.stress_total.mean, a.stress_total.mean);
  EXPECT_EQ(b.stress_total.err, a.stress_total.err);
  EXPECT_EQ(b.stress_virial.mean, a.stress_virial.mean);
  EXPECT_EQ(b.max_overlap_over_radius, a.max_overlap_over_radius);
  EXPECT_EQ(b.neighbor_builds, a.neighbor_builds);
  EXPECT_EQ(slurp(base / "cut/timeseries.csv"), slurp(base / "whole/timeseries.csv"));
  EXPECT_EQ(slurp(base / "cut/frames.xyz"), slurp(base / "whole/frames.xyz"));
  EXPECT_FALSE(std::filesystem::exists(base / "cut/checkpoint.bin"));  // removed once complete
}

TEST(Checkpoint, ResumedVerletRunEqualsUninterruptedBitForBit) { check_resume_reproduces("verlet_exp"); }
TEST(Checkpoint, ResumedOverdampedRunEqualsUninterruptedBitForBit) { check_resume_reproduces("overdamped"); }
TEST(Checkpoint, ResumedImplicitRunEqualsUninterruptedBitForBit) { check_resume_reproduces("implicit"); }

// (also: checkpoints of a run without frames; an unopened frame stream once broke them)
TEST(Checkpoint, RefusesACheckpointOfAnotherScene) {
  const auto base = std::filesystem::temp_directory_path() / "mrf_ckpt_other";
  std::filesystem::remove_all(base);
  RunOptions cut;
  cut.out_dir = base.string();
  cut.quiet = true;
  cut.checkpoint_every_rows = 100;
  cut.stop_after_steps = 200;  // of 320
  EXPECT_THROW(run_scene(scene("verlet_exp", 1.0, 0), cut), RunInterrupted);
  EXPECT_TRUE(std::filesystem::exists(base / "checkpoint.bin"));
  cut.stop_after_steps = 0;
  cut.resume = true;
  try {
    run_scene(scene("verlet_exp", 0.9, 0), cut);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "--resume") << e.what();
  }
}

}  // namespace
}  // namespace mrf
