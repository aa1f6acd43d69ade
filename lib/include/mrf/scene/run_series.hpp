// Pieces of a run loop shared by the DEM and the coupled runs: time-series
// rows (sums over the steps between two rows), the block-averaged stress
// series of the steady part, the timeseries.csv format, particle frames and
// the output files with checkpoints.
#pragma once
#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "mrf/integrate/implicit_stepper.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/observe/structure.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

// Running sums of one time-series row (stresses in Pa, overlap in m, J).
struct SeriesRow {
  double particles = 0, fluid = 0, vir_mag = 0, vir_con = 0, vir_fluid = 0, max_overlap = 0, e_dip = 0,
         e_hertz = 0;
  double n = 0;  // sum of the step weights
  ClusterStats clusters;  // of the configuration that ends the row (observe/structure.hpp)
  // One step of weight w (1 for fixed steps, the step length for the adaptive
  // implicit scheme): the particles' pair sums, the fluid's wall stress and
  // the fluid's virial stress (Pa; eta gdot for the imposed profile of model 1).
  void add(const PairSums& p, const Box& box, double fluid_stress, double fluid_virial, double w = 1.0);
};

// The structure (cluster statistics, the cost of a cell-list pass) is
// sampled at most once per this much strain: finer rows (a short benchmark
// run writes one per step) would spend more on it than on the dynamics, and
// the block average of the structure's error bar needs decorrelated samples,
// not more of them.
inline constexpr double k_structure_sample_strain = 1e-3;
// Rows between two structure samples for rows of `row_strain` each.
long structure_stride(double row_strain);

// Row means after the warm-up, block-averaged at the end (observe/block_average).
class StressSeries {
 public:
  // with_structure: row.clusters was measured (see structure_stride).
  void push(const SeriesRow& row, bool with_structure = true);
  // Rows pushed so far.
  std::size_t rows() const { return total_.size(); }
  // Fills stress_total, stress_particles, stress_fluid (mean), stress_virial
  // (particle pair virial; the fluid part is stress_fluid in every model),
  // its magnetic and contact parts, and wall_minus_virial (particle wall
  // stress - pair virial). The volume-side total, pair virial + fluid
  // virial, goes to extra["stress_virial_total"] (+ "_err") beside
  // extra["stress_virial_fluid"]: it must match stress_total in steady state.
  // The structure: extra["spanning_fraction"] (+ "_err"), the share of free
  // spheres in gap-spanning clusters, and extra["wall_cluster_fraction"].
  void finish(RunSummary& s) const;
  Measurement fluid() const;
  // Checkpoints: one field list for both directions, Self = StressSeries or
  // const StressSeries (Archive::io puts or gets each field).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.total_, s.particles_, s.fluid_, s.virial_, s.mag_, s.con_, s.diff_, s.vir_fluid_, s.vir_total_,
          s.spanning_, s.wall_clusters_);
  }
  void save(ArchiveWriter& a) const { serialize(a, *this); }
  void load(ArchiveReader& a) { serialize(a, *this); }

 private:
  std::vector<double> total_, particles_, fluid_, virial_, mag_, con_, diff_, vir_fluid_, vir_total_;
  std::vector<double> spanning_, wall_clusters_;  // ClusterStats of the rows that sampled it
};

// The fields of summary.json that come from the scene alone (model, Mn,
// shear rate, strains, material, carrier fluid, seed) and the thread count.
RunSummary scene_summary(const SceneConfig& c);

// The implicit scheme's work in summary.json: implicit_rejected_steps,
// _newton_failures, _newton_iterations, _linear_iterations and _dt_min/max
// (the run loop adds _dt_mean, the run's time over its steps).
void report_implicit(const ImplicitCounters& c, RunSummary& s);

// The counts of work in a summary that the model keeps over its whole life
// (steps, neighbor_builds and the extra keys that count iterations, failures
// and builds; run_series.cpp lists them), in that order: what a
// branch, which starts from another run's model, subtracts at its end so that
// its summary counts its own work. The extremes (implicit_dt_min/max,
// porosity_min/max) and momentum_drift_* stay those of the whole history.
// `pair_list_builds`: the model's builds of its free-free pair list; returns
// the run's own.
std::vector<double> work_counters(const RunSummary& s, long pair_list_builds);
long subtract_work(const std::vector<double>& before, RunSummary& s, long pair_list_builds);

void write_series_header(std::ostream& out);
void write_series_row(std::ostream& out, double time, double strain, const SeriesRow& row, double radius);

// Extended-XYZ frame of free and wall spheres (OVITO, ParaView): the count,
// a comment line with Lattice, Origin, Properties and Time=, then one line
// "Fe x y z radius" per free sphere and "W x y z radius" per wall sphere (m),
// positions to 17 significant digits (they read back exactly).
void write_frame(std::ostream& out, const ShearCell& cell, double radius, double time);

// The last frame of a frames.xyz that write_frame wrote: free and wall
// positions in file order, and its Time. InputError naming `key`, the file
// and the line on a file that is not such a frames file (a short frame, a
// species other than Fe or W, a count that does not match its lines).
struct Frame {
  std::vector<Vec3> free, walls;
  double time = 0;
};
Frame read_last_frame(const std::string& path, const std::string& key);

// Steps between rows (output.every or ~2000 rows) and the check that at
// least 32 rows follow the warm-up; throws InputError on output.every when
// the user set it, else on drive.strain (with what to change: a longer
// drive.strain, a shorter drive.warmup_strain, output.every where it helps).
long series_every(const LoadedScene& scene, long steps);

// What a run loop carries from one row to the next (checkpointed).
struct LoopState {
  long n = 0;                 // last completed step
  double row_start = 0;       // time at which the current row began (s)
  double strain_before = 0;   // strain reached by earlier sessions of this run
  StressSeries se;
  double max_overlap = 0;
  long pair_evals = 0;
  double elapsed_before = 0;  // wall seconds of earlier sessions of this run
  double cpu_before = 0;      // CPU seconds (all threads) of earlier sessions of this run
  std::uint64_t ts_bytes = 0, frames_bytes = 0;  // lengths of timeseries.csv and frames.xyz
  double t_origin = 0;  // the model's time when this run began: 0, or the parent's time for a branch (s)
  // A branch: the parent's work counters at the branch point (work_counters),
  // which its summary subtracts; empty for a run from the start.
  std::vector<double> work_before;
  template <class Archive, class Self>  // as StressSeries::serialize
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.n, s.row_start, s.strain_before, s.se, s.max_overlap, s.pair_evals, s.elapsed_before, s.cpu_before,
          s.ts_bytes, s.frames_bytes, s.t_origin, s.work_before);
  }
  void save(ArchiveWriter& a) const { serialize(a, *this); }
  void load(ArchiveReader& a) { serialize(a, *this); }
};

// Every parameter of the scene, exactly: a checkpoint resumes only into the same run.
std::string scene_fingerprint(const SceneConfig& c);
// Which scene keys two fingerprints disagree on, with both values ("drive.strain
// 24 in the checkpoint, 12 now; ..."): what a refused resume names.
std::string fingerprint_difference(const std::string& was, const std::string& now);
// The keys two fingerprints disagree on ("(format)" when one comes from
// another version of mrf).
std::vector<std::string> fingerprint_keys_differing(const std::string& was, const std::string& now);
// Whether a run may branch from another run's state when their scenes differ
// in `key`: the run's length, the output and the numerical choices that leave
// the state's layout alone (numerics.integrator and implicit_order do not).
bool branch_may_differ_in(const std::string& key);
// Its CRC-32 as 8 hex digits: summary.json's scene_id, by which a sweep
// archive tells a result of this scene from one of an edited scene.
std::string scene_id(const SceneConfig& c);
// The same CRC-32 of a fingerprint as read from a checkpoint.
std::string fingerprint_id(const std::string& fingerprint);

// The files of a run loop in RunOptions::out_dir (none when it is empty):
// timeseries.csv, frames.xyz, checkpoint.bin and summary.json. A checkpoint
// (an archive, io/archive.hpp: header, payload, checksum) holds the scene
// fingerprint, the LoopState and what the loop saves of its model; it is
// written atomically (temporary file + rename) at a row boundary every
// checkpoint_seconds of wall time (or checkpoint_every_rows rows) and removed
// when the run completes.
class RunFiles {
 public:
  using SaveModel = std::function<void(ArchiveWriter&)>;
  using LoadModel = std::function<void(ArchiveReader&)>;
  RunFiles(const RunOptions& opt, const SceneConfig& c);
  // With RunOptions::resume and a checkpoint in out_dir: verifies the archive
  // (NumericalError if it is foreign, of another version, truncated or
  // corrupt), checks its fingerprint (InputError on "--resume" if another
  // scene wrote it), loads `st`, then the model with `load_model`, which must
  // read the payload to its end. Nothing in out_dir changes before all of
  // this has succeeded. Opens timeseries.csv and, with
  // `with_frames`, frames.xyz: new, or cut back to the checkpoint and
  // appended to. Without a checkpoint to resume and with
  // RunOptions::branch_from: reads that archive (another run's checkpoint or
  // final state), refuses it (InputError on "--branch-from") if its scene
  // differs in a key branch_may_differ_in does not allow, and loads only the
  // model from it; `st` stays a new run's, its t_origin and row_start to be
  // set to the model's time by the caller. Returns how the run starts.
  enum class Start { fresh, resumed, branched };
  Start open(LoopState& st, bool with_frames, const LoadModel& load_model);
  // At a row boundary after step n, at `strain`: writes a checkpoint of `st`
  // at step n when one is due and the run goes on (`more`), or the final
  // state (out_dir/final_state.bin, with RunOptions::keep_final_state) when
  // it does not, then throws RunInterrupted when
  // RunOptions::stop_after_steps is reached.
  void end_row(const LoopState& st, long n, double strain, bool more, const SaveModel& save_model);
  // The run is complete: summary.json (atomically), then the checkpoint is removed.
  void finish(const RunSummary& s);
  // Wall and CPU seconds of this run up to now, over every session of a
  // resumed run (`st` carries the earlier sessions'). CPU time is the
  // process's, all threads: unlike wall time it leaves out a stopped process
  // (SIGSTOP) and the other jobs that share its cores.
  struct Elapsed {
    double wall = 0, cpu = 0;
  };
  Elapsed elapsed(const LoopState& st) const;
  const std::string& checkpoint() const { return checkpoint_; }

  std::ofstream series, frames;  // open when out_dir is set (frames when asked for)

 private:
  // flushes f and throws OutputError naming path and the system error if the write failed
  void check_written(std::ofstream& f, const std::string& path, long step);
  // an archive of the fingerprint, `st` at step n and strain, and the model (atomically)
  void write_state(const std::string& path, const LoopState& st, long n, double strain, const SaveModel& save_model,
                   std::chrono::steady_clock::time_point now);
  RunOptions opt_;
  double cpu_start_ = 0;  // the process's CPU seconds when this session began
  std::string checkpoint_, fingerprint_;
  std::chrono::steady_clock::time_point start_, last_checkpoint_;
  long rows_since_checkpoint_ = 0;
};

}  // namespace mrf
