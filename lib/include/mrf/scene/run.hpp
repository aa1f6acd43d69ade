// One run of a scene: the model built by build_model (scene/build_model.hpp)
// integrated to the requested strain by the one run loop; writes
// timeseries.csv, summary.json and checkpoints, and returns the summary.
#pragma once
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <cstdint>
#include "mrf/io/toml_scene.hpp"

namespace mrf {

struct RunOptions {
  std::string out_dir;  // empty: write nothing
  bool quiet = false;   // no progress or start-up table on stderr
  // Checkpoints (DEM and coupled runs): out_dir/checkpoint.bin, written atomically at a
  // time-series row boundary every `checkpoint_seconds` of wall time (or every
  // `checkpoint_every_rows` rows when > 0), removed when the run completes.
  // With `resume` a run continues from it and ends bit for bit as an
  // uninterrupted run would (the wall time aside).
  bool resume = false;
  // Start from the state in this archive (another run's checkpoint.bin or
  // final_state.bin) instead of the scene's initial state, when there is no
  // checkpoint to resume: the run goes on for drive.strain from the parent's
  // time, its warm-up counted from there. Its scene may differ from the
  // parent's only in numerical choices (branch_may_differ_in,
  // scene/run_series.hpp): two branches of one state compare those choices
  // on the same trajectory.
  std::string branch_from = {};
  // Keep the state at the end (out_dir/final_state.bin), for branches.
  bool keep_final_state = false;
  double checkpoint_seconds = 60;
  long checkpoint_every_rows = 0;
  // Tests: throw RunInterrupted after this step (fluid step of a coupled run), as a kill would stop the run.
  long stop_after_steps = 0;
};

// Thrown by run_scene when RunOptions::stop_after_steps is reached.
struct RunInterrupted : std::runtime_error {
  explicit RunInterrupted(long step) : std::runtime_error("run stopped at step " + std::to_string(step)) {}
};

struct Measurement {
  double mean = 0, err = 0, drift_z = 0, independent_samples = 0;
};

struct RunSummary {
  std::string model, integrator, binding_limit;
  double mason = 0, shear_rate = 0, strain = 0, warmup_strain = 0, dt = 0;
  Measurement stress_total, stress_particles, stress_virial, stress_virial_magnetic,
      stress_virial_contact, wall_minus_virial;
  double stress_fluid = 0;
  long n_particles = 0, n_wall = 0, n_fluid = 0, steps = 0, neighbor_builds = 0;
  double wall_seconds = 0, particle_steps_per_second = 0, pair_evaluations_per_second = 0;
  double cpu_seconds = 0;  // the process's CPU time over the run (all threads, every session of a resumed run)
  double stokes_number = 0, reynolds_number = 0, max_overlap_over_radius = 0;
  double youngs_modulus = 0, density = 0, magnetization = 0, volume_fraction = 0;
  double viscosity = 0, fluid_density = 0;  // carrier fluid: Pa s, kg/m^3
  std::uint64_t seed = 0;
  int threads = 1;
  std::string scene_id;  // CRC-32 (8 hex digits) of scene_fingerprint: which scene this measured (mrf sweep --archive)
  std::map<std::string, double> extra;  // model-specific keys, written into summary.json as they are
};

RunSummary run_scene(const LoadedScene& scene, const RunOptions& opt);

// summary.json text of a run (every key of DESIGN.md plus the extras above).
std::string summary_json(const RunSummary& s);

}  // namespace mrf
