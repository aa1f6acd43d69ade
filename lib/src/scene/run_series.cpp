#include "mrf/scene/run_series.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <sstream>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "mrf/error.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/observe/block_average.hpp"
#include "mrf/observe/steady_state.hpp"
#include "mrf/observe/stress.hpp"

namespace mrf {

namespace {

Measurement measure(const std::vector<double>& v) {
  const BlockAverage b = block_average(v);
  return {b.mean, b.sem, b.drift_z, b.independent_samples};
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

void SeriesRow::add(const PairSums& p, const Box& box, double fluid_stress, double fluid_virial, double w) {
  vir_fluid += w * fluid_virial;
  particles += w * wall_shear_stress(p.wall_fz, box);
  fluid += w * fluid_stress;
  vir_mag += w * virial_shear_stress(p.virial_mag_xz, box);
  vir_con += w * virial_shear_stress(p.virial_con_xz, box);
  max_overlap = std::max(max_overlap, p.max_overlap);
  e_dip += w * p.energy_dipole;
  e_hertz += w * p.energy_hertz;
  n += w;
}

long structure_stride(double row_strain) {
  if (!(row_strain > 0)) return 1;
  return std::max(1L, static_cast<long>(std::ceil(k_structure_sample_strain / row_strain * (1 - 1e-9))));
}

void StressSeries::push(const SeriesRow& r, bool with_structure) {
  const double k = 1.0 / r.n;
  const double tp = r.particles * k, tf = r.fluid * k, vm = r.vir_mag * k, vc = r.vir_con * k;
  total_.push_back(tp + tf);
  particles_.push_back(tp);
  fluid_.push_back(tf);
  virial_.push_back(vm + vc);
  mag_.push_back(vm);
  con_.push_back(vc);
  diff_.push_back(tp - vm - vc);
  vir_fluid_.push_back(r.vir_fluid * k);
  vir_total_.push_back(vm + vc + r.vir_fluid * k);
  if (!with_structure) return;
  spanning_.push_back(r.clusters.spanning_fraction);
  wall_clusters_.push_back(r.clusters.wall_fraction);
}

Measurement StressSeries::fluid() const { return measure(fluid_); }

void StressSeries::finish(RunSummary& s) const {
  s.stress_total = measure(total_);
  s.stress_particles = measure(particles_);
  s.stress_fluid = measure(fluid_).mean;
  s.stress_virial = measure(virial_);
  s.stress_virial_magnetic = measure(mag_);
  s.stress_virial_contact = measure(con_);
  s.wall_minus_virial = measure(diff_);
  const Measurement vt = measure(vir_total_);
  s.extra["stress_virial_total"] = vt.mean;
  s.extra["stress_virial_total_err"] = vt.err;
  s.extra["stress_virial_fluid"] = measure(vir_fluid_).mean;
  const Measurement span = measure(spanning_);
  s.extra["spanning_fraction"] = span.mean;
  s.extra["spanning_fraction_err"] = span.err;
  s.extra["wall_cluster_fraction"] = measure(wall_clusters_).mean;
  // steady-state check: the share of the averaging window MSER-5 would still
  // discard as transient (0 = steady from the end of the warm-up)
  s.extra["steady_mser_discard_fraction"] =
      total_.empty() ? 0.0 : static_cast<double>(mser_truncation(total_)) / static_cast<double>(total_.size());
}

RunSummary scene_summary(const SceneConfig& c) {
  RunSummary s;
  s.model = to_string(c.model);
  s.mason = c.mason;
  s.shear_rate = c.shear_rate;
  s.strain = c.strain;
  s.warmup_strain = c.warmup_strain;
  s.youngs_modulus = c.youngs_modulus;
  s.density = c.density;
  s.magnetization = c.magnetization;
  s.volume_fraction = c.volume_fraction;
  s.viscosity = c.viscosity;
  s.fluid_density = c.fluid_density;
  s.seed = c.seed;
  s.threads = omp_get_max_threads();
  s.scene_id = scene_id(c);
  return s;
}

void report_implicit(const ImplicitCounters& c, RunSummary& s) {
  s.extra["implicit_rejected_steps"] = static_cast<double>(c.rejected);
  s.extra["implicit_newton_failures"] = static_cast<double>(c.newton_failures);
  s.extra["implicit_newton_iterations"] = static_cast<double>(c.newton_iterations);
  s.extra["implicit_linear_iterations"] = static_cast<double>(c.linear_iterations);
  s.extra["implicit_dt_min"] = c.dt_min;
  s.extra["implicit_dt_max"] = c.dt_max;
}

namespace {
// The extra keys of summary.json that count work over a model's life.
constexpr const char* k_work_keys[] = {"implicit_rejected_steps", "implicit_newton_failures",
                                       "implicit_newton_iterations", "implicit_linear_iterations",
                                       "fluid_steps", "sph_pair_builds", "viscous_cg_iterations",
                                       "coupling_pair_builds", "steps_with_clamped_porosity", "sph_wall_reflections"};
}  // namespace

std::vector<double> work_counters(const RunSummary& s, long pair_list_builds) {
  std::vector<double> w = {static_cast<double>(s.steps), static_cast<double>(s.neighbor_builds),
                           static_cast<double>(pair_list_builds)};
  for (const char* key : k_work_keys) {
    const auto it = s.extra.find(key);
    w.push_back(it == s.extra.end() ? 0.0 : it->second);
  }
  return w;
}

long subtract_work(const std::vector<double>& before, RunSummary& s, long pair_list_builds) {
  if (before.empty()) return pair_list_builds;
  if (before.size() != 3 + std::size(k_work_keys))
    throw CheckpointError("a branch's work counters hold " + std::to_string(before.size()) + " values, this build keeps " +
                          std::to_string(3 + std::size(k_work_keys)));
  s.steps -= static_cast<long>(before[0]);
  s.neighbor_builds -= static_cast<long>(before[1]);
  std::size_t k = 3;
  for (const char* key : k_work_keys) {
    const auto it = s.extra.find(key);
    if (it != s.extra.end()) it->second -= before[k];
    ++k;
  }
  return pair_list_builds - static_cast<long>(before[2]);
}

void write_series_header(std::ostream& out) {
  out << "time_s,strain,stress_total_Pa,stress_particles_Pa,stress_fluid_Pa,"
         "stress_virial_magnetic_Pa,stress_virial_contact_Pa,max_overlap_over_radius,"
         "energy_dipole_J,energy_hertz_J\n";
}

void write_series_row(std::ostream& out, double time, double strain, const SeriesRow& r, double radius) {
  const double k = 1.0 / r.n;
  out << time << "," << strain << "," << (r.particles + r.fluid) * k << "," << r.particles * k << ","
      << r.fluid * k << "," << r.vir_mag * k << "," << r.vir_con * k << "," << r.max_overlap / radius << ","
      << r.e_dip * k << "," << r.e_hertz * k << "\n";
}

void write_frame(std::ostream& out, const ShearCell& cell, double radius, double time) {
  // max_digits10: the positions read back exactly (mrf quasistatic --start-from).
  const std::streamsize precision = out.precision(std::numeric_limits<double>::max_digits10);
  out << cell.free.size() + cell.walls.size() << "\n";
  out << "Lattice=\"" << cell.box.gap + 2 * radius << " 0 0 0 " << cell.box.ly << " 0 0 0 " << cell.box.lz
      << "\" Origin=\"" << -0.5 * cell.box.gap - radius
      << " 0 0\" Properties=species:S:1:pos:R:3:radius:R:1 Time=" << time << "\n";
  for (const auto& x : cell.free.x) out << "Fe " << x.x() << " " << x.y() << " " << x.z() << " " << radius << "\n";
  for (const auto& x : cell.walls.x) out << "W " << x.x() << " " << x.y() << " " << x.z() << " " << radius << "\n";
  out.precision(precision);
}

Frame read_last_frame(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  if (!in) throw InputError(key, path, "", std::string("cannot read: ") + std::strerror(errno));
  Frame last;
  bool any = false;
  long line_no = 0;
  std::string line;
  const auto bad = [&](const std::string& why) {
    return InputError(key, path, "line " + std::to_string(line_no), why + " (expected a frames.xyz of mrf run)");
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::size_t count = 0;
    {
      std::istringstream head(line);
      if (!(head >> count) || count == 0) throw bad("not a particle count: '" + line + "'");
    }
    Frame f;
    if (!std::getline(in, line)) throw bad("frame ends after its count");
    ++line_no;
    const std::size_t at = line.find("Time=");
    if (at == std::string::npos) throw bad("comment line without Time=");
    f.time = std::strtod(line.c_str() + at + 5, nullptr);
    for (std::size_t k = 0; k < count; ++k) {
      if (!std::getline(in, line)) throw bad("frame of " + std::to_string(count) + " spheres ends after " + std::to_string(k));
      ++line_no;
      std::istringstream row(line);
      std::string species;
      double x = 0, y = 0, z = 0, r = 0;
      if (!(row >> species >> x >> y >> z >> r) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        throw bad("not 'species x y z radius' with finite numbers: '" + line + "'");
      if (species == "Fe")
        f.free.emplace_back(x, y, z);
      else if (species == "W")
        f.walls.emplace_back(x, y, z);
      else
        throw bad("species '" + species + "' is neither Fe (free) nor W (wall)");
    }
    last = std::move(f);
    any = true;
  }
  if (!any) throw InputError(key, path, "", "holds no frame");
  return last;
}

long series_every(const LoadedScene& scene, long steps) {
  const SceneConfig& c = scene.config;
  const bool automatic = c.every <= 0;  // output.every not set (or 0): about 2000 rows per run
  const long every = automatic ? std::max(1L, steps / 2000) : c.every;
  const double rows_after_warmup = (1.0 - c.warmup_strain / c.strain) * static_cast<double>(steps / every);
  if (rows_after_warmup >= 32) return every;
  const std::string rows = std::to_string(static_cast<long>(rows_after_warmup));
  auto num = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", x);
    return std::string(buf);
  };
  if (!automatic)
    throw InputError("output.every", std::to_string(every), scene.locate("output.every"),
                     "leaves only " + rows +
                         " time-series rows after the warm-up; block averaging needs at least 32 (set a smaller "
                         "output.every, a longer drive.strain or a shorter drive.warmup_strain)");
  // output.every is automatic: the user set the strains, so name drive.strain and what to change.
  const double strain_per_row = c.strain * static_cast<double>(every) / static_cast<double>(std::max(1L, steps));
  const double strain_needed = c.warmup_strain + 32.0 * strain_per_row;
  std::string why = "with drive.warmup_strain = " + num(c.warmup_strain) + " (" + scene.locate("drive.warmup_strain") +
                    ") leaves only " + rows + " time-series rows after the warm-up (one row per strain " +
                    num(strain_per_row) + ", " + std::to_string(steps / every) +
                    " in all); block averaging needs at least 32: give a longer drive.strain (at least about " +
                    num(strain_needed) + ") or a shorter drive.warmup_strain";
  why += every > 1 ? ", or set output.every below the automatic " + std::to_string(every) + " steps per row"
                   : " (output.every cannot add rows: they are already one per time step)";
  throw InputError("drive.strain", num(c.strain), scene.locate("drive.strain"), why);
}


RunFiles::RunFiles(const RunOptions& opt, const SceneConfig& c)
    : opt_(opt),
      checkpoint_(opt.out_dir.empty() ? "" : opt.out_dir + "/checkpoint.bin"),
      fingerprint_(scene_fingerprint(c)) {}

RunFiles::Start RunFiles::open(LoopState& st, bool with_frames, const LoadModel& load_model) {
  bool resumed = false;
  Start start = Start::fresh;
  if (opt_.resume && !checkpoint_.empty() && std::filesystem::exists(checkpoint_)) {
    ArchiveReader in(checkpoint_);
    std::string fp;
    in.get(fp);
    if (fp != fingerprint_)
      throw InputError("--resume", checkpoint_, "",
                       "the checkpoint was written by a run with different scene parameters (" +
                           fingerprint_difference(fp, fingerprint_) + "); remove it or use another --out");
    st.load(in);
    load_model(in);
    in.expect_end();
    resumed = true;
    start = Start::resumed;
  } else if (!opt_.branch_from.empty()) {
    ArchiveReader in(opt_.branch_from);
    std::string fp;
    in.get(fp);
    std::string refused;
    for (const std::string& key : fingerprint_keys_differing(fp, fingerprint_))
      if (!branch_may_differ_in(key)) refused += (refused.empty() ? "" : ", ") + key;
    if (!refused.empty())
      throw InputError("--branch-from", opt_.branch_from, "",
                       "a branch may differ from its parent only in drive.strain, drive.warmup_strain, scene.seed, "
                       "output.* and the numerical keys that leave the state's layout alone; this one differs in " +
                           refused + " (" + fingerprint_difference(fp, fingerprint_) + ")");
    LoopState parent;  // the parent's accumulators are not this run's
    parent.load(in);
    load_model(in);
    in.expect_end();
    start = Start::branched;
  }
  if (!opt_.out_dir.empty()) {
    std::filesystem::create_directories(opt_.out_dir);
    const std::string ts = opt_.out_dir + "/timeseries.csv", fr = opt_.out_dir + "/frames.xyz";
    errno = 0;
    if (resumed) {  // drop rows written after the checkpoint, then append
      const auto need = [&](const std::string& file, std::uintmax_t bytes) {
        std::error_code ec;
        const std::uintmax_t have = std::filesystem::file_size(file, ec);
        if (ec || have < bytes)
          throw CheckpointError("cannot resume from " + checkpoint_ + ": " + file +
                                (ec ? " is missing" : " has " + std::to_string(have) + " bytes") + ", the checkpoint was written after " +
                                std::to_string(bytes) + " of them; the rows before it are lost: remove the checkpoint to start over");
      };
      need(ts, st.ts_bytes);
      if (with_frames) need(fr, st.frames_bytes);
      std::filesystem::resize_file(ts, st.ts_bytes);
      series.open(ts, std::ios::app);
    } else {
      series.open(ts);
      write_series_header(series);
    }
    series.precision(10);
    if (!series) throw OutputError("cannot write " + ts + ": " + std::strerror(errno));
    if (with_frames) {
      if (resumed) std::filesystem::resize_file(fr, st.frames_bytes);
      frames.open(fr, resumed ? std::ios::app : std::ios::out);
      if (!frames) throw OutputError("cannot write " + fr + ": " + std::strerror(errno));
    }
  }
  start_ = last_checkpoint_ = std::chrono::steady_clock::now();
  cpu_start_ = process_cpu_seconds();
  return start;
}

RunFiles::Elapsed RunFiles::elapsed(const LoopState& st) const {
  return {st.elapsed_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(),
          st.cpu_before + process_cpu_seconds() - cpu_start_};
}

bool branch_may_differ_in(const std::string& key) {
  // not numerics.skin: the Verlet lists, and with them the skin in use,
  // come from the parent's state, so a branch would run (and report) the
  // parent's skin whatever its scene said
  static const char* const allowed[] = {"drive.strain",          "drive.warmup_strain", "scene.seed",
                                        "numerics.dt",           "numerics.dt_safety",  "numerics.implicit_tol",
                                        "numerics.threads",      "numerics.newton_tol", "output.every",
                                        "output.frames"};
  return std::find(std::begin(allowed), std::end(allowed), key) != std::end(allowed);
}

void RunFiles::check_written(std::ofstream& f, const std::string& path, long step) {
  errno = 0;
  f.flush();
  if (f) return;
  std::ostringstream m;
  m << "write failed: " << path << " at step " << step << ": " << std::strerror(errno)
    << "; the run stops (its last checkpoint, if any, is intact: --resume continues from it once there is room)";
  throw OutputError(m.str());
}

void RunFiles::end_row(const LoopState& st, long n, double strain, bool more, const SaveModel& save_model) {
  const auto now = std::chrono::steady_clock::now();
  ++rows_since_checkpoint_;
  // every row reaches the file at once, so a full disk stops the run at the
  // row it hit, not silently at the end
  if (series.is_open()) check_written(series, opt_.out_dir + "/timeseries.csv", n);
  if (frames.is_open()) check_written(frames, opt_.out_dir + "/frames.xyz", n);
  const bool due = opt_.checkpoint_every_rows > 0
                       ? rows_since_checkpoint_ >= opt_.checkpoint_every_rows
                       : opt_.checkpoint_seconds > 0 &&
                             std::chrono::duration<double>(now - last_checkpoint_).count() > opt_.checkpoint_seconds;
  if (!checkpoint_.empty() && due && more) {
    write_state(checkpoint_, st, n, strain, save_model, now);
    last_checkpoint_ = now;
    rows_since_checkpoint_ = 0;
  }
  if (!checkpoint_.empty() && opt_.keep_final_state && !more)
    write_state(opt_.out_dir + "/final_state.bin", st, n, strain, save_model, now);
  if (opt_.stop_after_steps > 0 && n >= opt_.stop_after_steps) throw RunInterrupted(n);
}

void RunFiles::write_state(const std::string& path, const LoopState& st, long n, double strain,
                           const SaveModel& save_model, std::chrono::steady_clock::time_point now) {
  LoopState snap = st;
  snap.n = n;
  snap.strain_before = strain;
  snap.elapsed_before += std::chrono::duration<double>(now - start_).count();
  snap.cpu_before += process_cpu_seconds() - cpu_start_;
  series.flush();
  snap.ts_bytes = static_cast<std::uint64_t>(std::filesystem::file_size(opt_.out_dir + "/timeseries.csv"));
  if (frames.is_open()) {
    frames.flush();
    snap.frames_bytes = static_cast<std::uint64_t>(std::filesystem::file_size(opt_.out_dir + "/frames.xyz"));
  }
  ArchiveWriter out(path);
  out.put(fingerprint_);
  snap.save(out);
  save_model(out);
  out.close();  // atomic: a kill while writing leaves the previous file
}

void RunFiles::finish(const RunSummary& s) {
  if (opt_.out_dir.empty()) return;
  write_file_atomic(opt_.out_dir + "/summary.json", summary_json(s) + "\n");
  std::filesystem::remove(checkpoint_);  // the run is complete; summary.json is its record
}

}  // namespace mrf
