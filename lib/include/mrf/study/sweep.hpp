// A sweep: a grid of models x Mason numbers x seeds over one base scene
// (DESIGN.md, `mrf sweep`). Each point is an independent run with its own
// output folder; a point whose summary.json exists is finished and skipped,
// so a killed sweep resumes where it stopped. Points are dealt to ranks
// round-robin (index % size == rank), so `mpirun -n K mrf sweep` splits the
// grid without any communication.
//
// Sweep file (TOML; paths relative to the sweep file):
//   [sweep]
//   scene  = "../scenes/small_dem_stokes.toml"
//   models = ["dem_stokes", "demsph_stokes", "demsph_dd"]
//   mason  = [1e-3, 1e-2, 1e-1, 1.0]
//   seeds  = [1, 2]
//   set    = ["drive.strain=6"]          # overrides for every point (optional)
//   [[rule]]                              # extra overrides for matching points (optional)
//   mason_max = 2e-3                      # matches mason <= mason_max (optional)
//   mason_min = 0.5                       # matches mason >= mason_min (optional)
//   models = ["dem_stokes"]               # matches these models (optional)
//   set = ["drive.strain=3"]
//   [[variant]]                           # optional: the grid runs once per variant
//   name = "sph_fine"                     # folder-safe: letters, digits, _ . -
//   set = ["fluid.sph_spacing='7.5 um'"]  # applied after the rules
//   mason = [1e-2, 1.0]                   # optional: this variant's Mason numbers instead of sweep.mason
//   models = ["demsph_dd"]                # optional: run with these of the sweep's models only
// With variants the grid is model x variant x Mn x seed (variant after
// model in the index order), a point's folder is <model>/<variant>/mn_..,
// and sweep.mason may be left out when every variant gives its own.
// Errors are InputErrors naming the key and FILE:LINE.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "mrf/io/atomic_file.hpp"

namespace mrf {

struct SweepRule {
  double mason_min = 0, mason_max = 0;  // 0 = no bound
  std::vector<std::string> models;      // empty = all
  std::vector<std::uint64_t> seeds;     // empty = all (a longer run for the seeds that failed a steadiness test)
  // empty = every point, its overrides before the variant's; else the
  // variants it refines, its overrides after theirs (a longer run of one
  // convergence variant that failed a steadiness test)
  std::vector<std::string> variants;
  std::vector<std::string> set;
};

// A named set of overrides the whole grid is run with (convergence in one
// numerical choice, the conditions of a held-out design).
struct SweepVariant {
  std::string name;
  std::vector<std::string> set;
  std::vector<double> mason;  // empty: the sweep's
  std::vector<std::string> models;  // the models it runs with; empty: all of the sweep's
};

struct SweepSpec {
  std::string source;      // sweep file path (for messages)
  std::string scene_path;  // resolved base scene path
  std::vector<std::string> models;
  std::vector<double> mason;
  std::vector<std::uint64_t> seeds;
  std::vector<std::string> set;
  std::vector<SweepRule> rules;
  std::vector<SweepVariant> variants;  // empty: one grid, no variant folder level
};

struct SweepPoint {
  std::size_t index = 0;          // position in the grid (model-major, then variant, mason, seed)
  std::string model;
  double mason = 0;
  std::uint64_t seed = 0;
  std::string variant;            // its name, empty without variants
  std::vector<std::string> sets;  // every override of this point, in order
  std::string dir;                // output folder relative to the sweep output, e.g. dem_stokes/mn_0.01_seed_1
};

SweepSpec load_sweep(const std::string& path);
SweepSpec parse_sweep(const std::string& toml_text, const std::string& source, const std::string& base_dir);

// The grid in a fixed order; every point carries scene.model, drive.mason
// and scene.seed overrides after the sweep-wide and rule overrides.
std::vector<SweepPoint> sweep_points(const SweepSpec& spec);

// Indices of the points that rank `rank` of `size` runs (round-robin).
std::vector<std::size_t> points_of_rank(std::size_t n_points, int rank, int size);

// Rank and size from the MPI launcher's environment (Open MPI
// OMPI_COMM_WORLD_RANK/SIZE, or PMI_RANK/PMI_SIZE); {0, 1} outside mpirun.
struct RankInfo {
  int rank = 0, size = 1;
};
RankInfo rank_from_environment();

// A point is finished when its summary.json (written last, atomically) or its
// failure.json exists and reads as a JSON object; delete the folder of a
// failed point to run it again. A record that does not read (a damaged file)
// leaves the point unfinished, so a sweep runs it again (point_record_damaged
// says so).
bool point_finished(const std::string& point_dir);
// The folder holds a summary.json or failure.json that does not read as a
// JSON object.
bool point_record_damaged(const std::string& point_dir);

// How far an unfinished point's run has come: the strain of the last row of
// its timeseries.csv, 0 when it has none or no checkpoint.bin to resume from
// (a run without one starts again from zero). Rows written after the last
// checkpoint are counted, so this may be ahead of where a resumed run
// restarts by up to one checkpoint interval.
double point_strain_reached(const std::string& point_dir);

// sweep.csv text: one row per point of `points` that has a summary.json or a
// failure.json under `out_dir`, with the DESIGN.md summary fields. With the
// sweep's spec, a folder made for another scene (folder_scene_id differs
// from the point's) gets status `stale` and no fields: no table reads it as
// the point's (set_aside_stale moves it when the point runs).
std::string sweep_csv(const std::vector<SweepPoint>& points, const std::string& out_dir,
                      const SweepSpec* spec = nullptr);
// out_dir/sweep.csv rewritten atomically from that text (the folder created
// if need be); returns the number of finished points (summary.json or
// failure.json, not stale).
std::size_t write_sweep_csv(const std::vector<SweepPoint>& points, const std::string& out_dir,
                            const SweepSpec* spec = nullptr);

struct SweepOptions {
  bool quiet = false;       // no progress on stderr
  RankInfo rank;            // which share of the grid this process runs
  long point = -1;          // >= 0: run this point of the grid alone (`--point K`, any scheduler), not a share
  double checkpoint_seconds = 60;  // wall seconds between a point's checkpoints (RunOptions)
  bool write_csv = true;           // rewrite sweep.csv at the end (MPI workers leave it to rank 0)
  double cost_rate = 1e6;   // particle-steps per second assumed by the first estimate
  std::string archive;      // non-empty: a sweep archive (below), restored from first, added to as points finish
  std::vector<std::string> calibrate;  // folders of summaries that calibrate the estimates only (estimate_points)
};

struct SweepOutcome {
  std::size_t ran = 0, skipped = 0, failed = 0;
  std::size_t elsewhere = 0;  // points another live process was running (their claim held: point_claim.hpp)
  std::size_t refused = 0;    // points whose checkpoint was refused (another format version, damaged): left as they are
  double estimated_seconds = 0;  // of this rank's unfinished points, before starting
  double seconds = 0;            // wall time spent
};

// Estimated wall time (s) of one point: steps from the automatic time step,
// times (free + wall [+ fluid]) particles, over `cost_rate`. NaN when the
// time step cannot be estimated for the model.
double estimate_point_seconds(const std::string& scene_path, const std::vector<std::string>& sets, double cost_rate);

// Estimates of every point, calibrated by the points already finished under
// out_dir: a finished point's own wall time; an unfinished one, the
// seconds_per_strain of the finished point of the same model nearest in
// log Mn, times its strain (the particle-steps estimate, which is blind to
// the implicit schemes' step sizes, only where no point of the model has
// finished). `calibrated[k]` says which of the two an estimate is. With an
// archive (--archive), its summaries calibrate too, by their seconds per
// strain unit, where out_dir has none; so do those of calibrate_dirs
// (--calibrate-from, repeatable: folders laid out like an archive, read for
// the cost alone and never restored), the first that has the point, where
// neither has it; for a point of a variant, the same model, Mn and seed
// without the variant level there calibrates too (a convergence sweep
// estimated from its own earlier runs, then from its base sweep), and then
// the same model, variant and Mn at another seed there (more seeds of a
// finished point, estimated before any of them ran).
struct PointEstimates {
  std::vector<double> seconds;
  std::vector<char> calibrated;
};
PointEstimates estimate_points(const SweepSpec& spec, const std::vector<SweepPoint>& points, const std::string& out_dir,
                               double cost_rate, const std::string& archive_dir = {},
                               const std::vector<std::string>& calibrate_dirs = {});

// Runs this rank's unfinished points one after another into out_dir/<point.dir>
// (every scene is loaded and validated before the first run, and so is the
// fluid of every SPH point against its box, as the coupled run checks it: an
// input error stops the sweep at once, naming the point). A point that fails numerically leaves
// failure.json with the message and the sweep goes on; a point whose
// checkpoint is refused (CheckpointError) is left as it is, said on stderr,
// and the sweep goes on; a finished point is skipped, and so is a point
// whose claim another live process holds (several processes may run one
// sweep output side by side: point_claim.hpp). Progress and an estimate of the time left go to stderr. At the
// end out_dir/sweep.csv is rewritten (atomically) from every finished point.
SweepOutcome run_sweep(const SweepSpec& spec, const std::string& out_dir, const SweepOptions& opt);

// A sweep archive (`mrf sweep FILE --archive DIR`): the summary.json of every
// finished point, in the layout of the sweep output
// (DIR/<model>/mn_<Mn>_seed_<s>/summary.json), small enough to commit, so that
// a sweep longer than one working period survives the loss of its output
// folder (a new machine, a scratch file system that is purged). An entry
// stands for a point only while its scene_id equals that of the point's scene
// as the sweep file now defines it: an edited scene, rule or override makes
// the entry stale, and a stale entry is reported and left alone (never used,
// never overwritten until the point has run again). A code change that moves
// the physics without changing the scene is not detected: clear the archive
// then (its entries carry the git revision that wrote them).
struct ArchiveSync {
  std::size_t restored = 0;  // entries copied into the output (points now finished there)
  std::vector<std::string> stale;  // point folders whose entry is for another scene
  // entries without a window_series.csv that got one from the finished run
  // in the output whose summary.json they hold
  std::size_t series_added = 0;
  // points finished in the output for their current scene whose entry was
  // missing or for another scene (a sweep killed between a point's end and
  // its archiving): archived now
  std::size_t archived = 0;
};
// A folder is changed only under the point's claim (study/point_claim.hpp):
// a point another process is running is left alone; `claimed`: the caller
// holds the claims of `points` already.
ArchiveSync restore_from_archive(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                 const std::string& out_dir, const std::string& archive_dir, bool claimed = false);
// Whether the archive holds a finished run of the point's scene as the
// sweep file now defines it (a readable summary.json with its scene_id):
// what a restore takes, --list calls archived and --estimate finished.
bool archive_entry_current(const SweepSpec& spec, const SweepPoint& p, const std::string& archive_dir);
// Copies a finished point's summary.json into the archive (atomically),
// with its averaging window's series (window_series.csv, io/timeseries.hpp)
// when the run wrote a time series; a point without a summary (failed,
// unfinished) leaves the archive as it is.
void archive_point(const SweepPoint& p, const std::string& out_dir, const std::string& archive_dir);
// What a restore did, on stderr (nothing when quiet).
void report_archive(const ArchiveSync& sync, const std::string& archive_dir, bool quiet);

// The scene_id a point folder's run was made for (summary.json,
// failure.json, or the checkpoint's fingerprint); empty when it cannot be
// told.
std::string folder_scene_id(const std::filesystem::path& dir);
// Whether the folder holds a run made for another scene than the point's.
bool point_stale(const SweepSpec& spec, const SweepPoint& p, const std::filesystem::path& dir);

// The same rule for the sweep output itself, applied by the process that
// runs the points (run_sweep for its share, the MPI master for the grid):
// a point folder made for another scene (the scene_id of its summary.json
// or failure.json, or of its checkpoint's fingerprint, differs from the
// point's as the sweep file now defines it: a rule, an override or the
// scene edited since) is moved to <folder>.stale-<its scene_id>, replacing
// an earlier one of that scene, so that the point runs again from the start;
// and a finished run of the point's own scene found under
// <folder>.stale-<scene_id> (a sweep file edited and then reverted) comes
// back instead of running again. A folder whose scene cannot be told (no
// scene_id: an older mrf; a damaged checkpoint) is left alone, and so is
// one whose point another process is running (its claim is held: the
// folder is moved only under the claim; `claimed`: the caller holds the
// claims of `points` already). Returns the point folders moved aside; says
// so on stderr unless quiet.
std::vector<std::string> set_aside_stale(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                         const std::string& out_dir, bool quiet, bool claimed = false);
// Point p finished in out_dir for its scene as the sweep now defines it (a
// finished folder of another scene, which a running process may still hold,
// is not).
bool point_finished(const SweepSpec& spec, const SweepPoint& p, const std::string& out_dir);
// The share of point p's run in out_dir still to go, 1 - reached / strain
// in [0, 1] (point_strain_reached; 1 for a folder of another scene, whose
// run this one does not continue): what scales its estimate into the time
// left.
double point_fraction_left(const SweepSpec& spec, const SweepPoint& p, const std::string& out_dir);

}  // namespace mrf
