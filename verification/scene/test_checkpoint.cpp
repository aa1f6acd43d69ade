// Checkpoint and resume (issue 6): a run killed after a checkpoint and
// resumed ends bit for bit as the uninterrupted run, for the DEM run and the
// coupled DEM-SPH runs; a checkpoint never resumes into a different scene.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/run_series.hpp"

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

// The loop state a checkpoint holds (after the scene's fingerprint).
LoopState checkpointed_loop(const std::filesystem::path& path) {
  ArchiveReader in(path.string());
  std::string fingerprint;
  in.get(fingerprint);
  LoopState st;
  st.load(in);
  return st;
}

// Run times: CPU seconds are counted (one thread: at most the wall time) and
// a resumed run's include its first session's, as its wall seconds do.
void check_run_times(const RunSummary& whole, const RunSummary& resumed, const LoopState& first) {
  ASSERT_EQ(whole.threads, 1);
  EXPECT_GT(whole.cpu_seconds, 0.0);
  EXPECT_LE(whole.cpu_seconds, whole.wall_seconds * 1.05 + 0.02);
  EXPECT_GT(first.cpu_before, 0.0);
  EXPECT_GT(first.elapsed_before, 0.0);
  EXPECT_GE(resumed.cpu_seconds, first.cpu_before);
  EXPECT_GE(resumed.wall_seconds, first.elapsed_before);
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

  const LoopState first = checkpointed_loop(base / "cut/checkpoint.bin");
  cut.stop_after_steps = 0;
  cut.resume = true;
  const RunSummary b = run_scene(scene(integrator), cut);
  check_run_times(a, b, first);
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
    // it names what differs, with both values (M is fixed: Mn moves the shear rate too)
    EXPECT_NE(std::string(e.what()).find("drive.mason 1 in the checkpoint, 0.9 now"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("drive.shear_rate"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("drive.strain"), std::string::npos) << e.what();
  }
}

// The difference of two fingerprints names each key that differs, and a key
// that entered the fingerprint later (numerics.newton_tol: only a value
// other than its default) against the default it had before.
TEST(Checkpoint, FingerprintDifferenceNamesTheKeysThatDiffer) {
  const SceneConfig a = scene("implicit").config;
  SceneConfig b = a;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(a), scene_fingerprint(b)), "");
  b.seed = 7;
  b.strain = 2.5;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(a), scene_fingerprint(b)),
            "drive.strain 0.5 in the checkpoint, 2.5 now; scene.seed 1 in the checkpoint, 7 now");
  b = a;
  b.newton_tol = 1e-5;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(a), scene_fingerprint(b)),
            "numerics.newton_tol 1e-06 (default) in the checkpoint, 1e-05 now");
  SceneConfig c = a;  // a coupled model's default carrier: the common reference (since session 37)
  c.model = ModelId::demsph_dd;
  b = c;
  b.eos_reference = EosReference::start;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(c), scene_fingerprint(b)),
            "fluid.eos_reference common in the checkpoint, start now");
  b.newton_tol = 1e-7;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(b), scene_fingerprint(c)),
            "numerics.newton_tol 1e-07 in the checkpoint, 1e-06 (default) now; "
            "fluid.eos_reference start in the checkpoint, common now");
  b = a;
  b.model = ModelId::demsph_dd;
  EXPECT_EQ(fingerprint_difference(scene_fingerprint(a), scene_fingerprint(b)),
            "scene.model dem_stokes in the checkpoint, demsph_dd now; "
            "fluid.eos_reference start in the checkpoint, common now");  // model 1 enters no carrier
  // values apart beyond ten digits are shown with seventeen; dt unset is "auto"
  b = a;
  b.shear_rate = std::nextafter(a.shear_rate, 2 * a.shear_rate);
  b.dt = 1e-7;
  const std::string d = fingerprint_difference(scene_fingerprint(a), scene_fingerprint(b));
  EXPECT_NE(d.find("numerics.dt auto in the checkpoint, 1e-07 now"), std::string::npos) << d;
  EXPECT_NE(d.find("drive.shear_rate "), std::string::npos) << d;
  const std::size_t at = d.find("drive.shear_rate ");
  const std::string sr = d.substr(at, d.find(';', at) - at);
  EXPECT_GE(sr.size(), std::string("drive.shear_rate  in the checkpoint,  now").size() + 2 * 17) << sr;
  // a fingerprint of another layout (fewer fields) is named as such, not read by position
  std::string old = scene_fingerprint(a);
  old.erase(old.rfind(';'));
  EXPECT_NE(fingerprint_difference(old, scene_fingerprint(a)).find("another version of mrf"), std::string::npos);
}

// Coupled DEM-SPH runs (models 2 and 3) on the small scene at Mn 1: strain
// 0.6 in ~200 fluid steps (2 DEM sub-steps each), one row per fluid step;
// with integrator "implicit" (inertialess) at Mn 1e-2: ~100 steps with SPH
// sub-steps, a row per largest step.
LoadedScene coupled_scene(const std::string& model, double mason = 1.0, int frames = 5,
                          const std::string& integrator = "auto") {
  return load_scene(k_scene, {"scene.model=\"" + model + "\"", "drive.mason=" + std::to_string(mason),
                              "drive.strain=0.6", "drive.warmup_strain=0.0", "output.every=1",
                              "output.frames=" + std::to_string(frames),
                              "numerics.integrator=\"" + integrator + "\""});
}

// The coupled run killed after a checkpoint and resumed ends as the
// uninterrupted run: every summary value (wall time aside), the time series
// and the frames byte for byte. The resumed file keeps a marker put into the
// header of the killed run's time series: the run continued, it did not
// start over.
void check_coupled_resume_reproduces(const std::string& model, int frames, double mason = 1.0,
                                     const std::string& integrator = "auto") {
  const auto base =
      std::filesystem::temp_directory_path() / ("mrf_ckpt_" + model + std::to_string(frames) + integrator);
  std::filesystem::remove_all(base);
  RunOptions whole;
  whole.out_dir = (base / "whole").string();
  whole.quiet = true;
  whole.checkpoint_seconds = 0;
  const RunSummary a = run_scene(coupled_scene(model, mason, frames, integrator), whole);
  const bool inertialess = a.integrator.rfind("inertialess", 0) == 0;
  const long fluid_steps = inertialess ? a.steps : static_cast<long>(a.extra.at("fluid_steps"));  // the loop's steps
  ASSERT_GE(fluid_steps, 32);

  RunOptions cut = whole;
  cut.out_dir = (base / "cut").string();
  // rows by step (inertial) or by strain interval (inertialess, ~0.4 steps a row)
  cut.checkpoint_every_rows = inertialess ? 7 : 25;
  cut.stop_after_steps = fluid_steps * 2 / 3;
  if (!inertialess) {
    ASSERT_NE(cut.stop_after_steps % 25, 0) << "rows after the last checkpoint must be cut on resume";
  }
  EXPECT_THROW(run_scene(coupled_scene(model, mason, frames, integrator), cut), RunInterrupted);
  ASSERT_TRUE(std::filesystem::exists(base / "cut/checkpoint.bin"));
  EXPECT_FALSE(std::filesystem::exists(base / "cut/summary.json"));
  std::string ts = slurp(base / "cut/timeseries.csv");
  ASSERT_EQ(ts.substr(0, 6), "time_s");
  ts[0] = 'T';
  std::ofstream(base / "cut/timeseries.csv", std::ios::binary) << ts;

  const LoopState first = checkpointed_loop(base / "cut/checkpoint.bin");
  cut.stop_after_steps = 0;
  cut.resume = true;
  const RunSummary b = run_scene(coupled_scene(model, mason, frames, integrator), cut);
  check_run_times(a, b, first);
  EXPECT_EQ(b.steps, a.steps);
  EXPECT_EQ(b.stress_total.mean, a.stress_total.mean);
  EXPECT_EQ(b.stress_total.err, a.stress_total.err);
  EXPECT_EQ(b.stress_virial.mean, a.stress_virial.mean);
  EXPECT_EQ(b.stress_fluid, a.stress_fluid);
  EXPECT_EQ(b.max_overlap_over_radius, a.max_overlap_over_radius);
  EXPECT_EQ(b.neighbor_builds, a.neighbor_builds);
  for (const auto& [key, value] : a.extra) {  // porosity range, momentum drift, wall reflections, ...
    if (key == "seconds_per_strain") continue;
    EXPECT_EQ(b.extra.at(key), value) << key;
  }
  ts = slurp(base / "cut/timeseries.csv");
  EXPECT_EQ(ts[0], 'T') << "the resumed run rewrote the time series instead of continuing it";
  ts[0] = 't';
  EXPECT_EQ(ts, slurp(base / "whole/timeseries.csv"));
  EXPECT_EQ(std::filesystem::exists(base / "cut/frames.xyz"), frames > 0);
  EXPECT_EQ(slurp(base / "cut/frames.xyz"), slurp(base / "whole/frames.xyz"));
  EXPECT_FALSE(std::filesystem::exists(base / "cut/checkpoint.bin"));  // removed once complete
}

TEST(Checkpoint, ResumedCoupledDiFeliceRunEqualsUninterruptedBitForBit) {
  check_coupled_resume_reproduces("demsph_dd", 5);
}
TEST(Checkpoint, ResumedCoupledStokesRunWithoutFramesEqualsUninterruptedBitForBit) {
  check_coupled_resume_reproduces("demsph_stokes", 0);
}
TEST(Checkpoint, ResumedInertialessCoupledRunEqualsUninterruptedBitForBit) {
  check_coupled_resume_reproduces("demsph_dd", 3, 1e-2, "implicit");
}

// A coupled checkpoint resumes neither into another Mason number nor into
// another model, coupled or not.
TEST(Checkpoint, RefusesACoupledCheckpointOfAnotherScene) {
  const auto base = std::filesystem::temp_directory_path() / "mrf_ckpt_coupled_other";
  std::filesystem::remove_all(base);
  RunOptions cut;
  cut.out_dir = base.string();
  cut.quiet = true;
  cut.checkpoint_every_rows = 3;
  cut.stop_after_steps = 4;
  EXPECT_THROW(run_scene(coupled_scene("demsph_dd", 1.0, 0), cut), RunInterrupted);
  ASSERT_TRUE(std::filesystem::exists(base / "checkpoint.bin"));
  cut.stop_after_steps = 0;
  cut.resume = true;
  const LoadedScene others[] = {coupled_scene("demsph_dd", 0.9, 0), coupled_scene("demsph_stokes", 1.0, 0),
                                load_scene(k_scene, {"drive.mason=1.0", "drive.strain=0.6", "drive.warmup_strain=0.0",
                                                     "output.every=1", "output.frames=0",
                                                     "numerics.integrator=\"verlet_exp\""})};
  for (const LoadedScene& other : others) {
    try {
      run_scene(other, cut);
      ADD_FAILURE() << "expected InputError for " << to_string(other.config.model);
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "--resume") << e.what();
    }
  }
}

}  // namespace
}  // namespace mrf
