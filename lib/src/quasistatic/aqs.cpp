#include "mrf/quasistatic/aqs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"
#include "mrf/observe/steady_state.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

namespace {

void require(bool ok, const char* key, double value, const std::string& why) {
  if (!ok) throw InputError(std::string("quasistatic.") + key, format_short(value), "", why);
}

// The minimum image of the pair lists needs r_c + skin <= min(ly, lz)/2.
void check_cutoff(double rc, const DemParams& p, const Box& box, const std::string& key, const std::string& where) {
  if (!(rc > 2.0 * p.radius))
    throw InputError(key, format_short(rc) + " m", where, "must be > 2*radius = " + format_short(2.0 * p.radius) + " m");
  const double half = 0.5 * std::min(box.ly, box.lz);
  if (rc + p.skin > half)
    throw InputError(key, format_short(rc) + " m", where,
                     "cut-off + skin = " + format_short(rc + p.skin) + " m exceeds min(box.ly, box.lz)/2 = " + format_short(half) +
                         " m (minimum image)");
}

void record(QuasistaticResult& r, const QuasistaticPoint& pt) {
  r.strain.push_back(pt.strain);
  r.stress_wall.push_back(pt.stress_wall);
  r.stress_virial.push_back(pt.stress_virial);
  r.stress_virial_magnetic.push_back(pt.stress_virial_magnetic);
  r.stress_virial_contact.push_back(pt.stress_virial_contact);
  r.energy.push_back(pt.energy);
  r.max_force.push_back(pt.max_force);
  r.max_overlap.push_back(pt.max_overlap);
  r.iterations.push_back(pt.iterations);
}

// Relative tolerance of a repeated minimum: far above the minimiser's
// round-off, far below any physical change of the stress.
constexpr double k_orbit_rel_tol = 1e-6;

// Steady part: strain >= warmup, then the MSER-5 cut of the wall stress.
void steady_averages(QuasistaticResult& r, double warmup) {
  std::size_t first = 0;
  while (first < r.strain.size() && r.strain[first] < warmup - 1e-12) ++first;
  if (first >= r.strain.size()) return;
  std::vector<double> wall(r.stress_wall.begin() + static_cast<long>(first), r.stress_wall.end());
  std::vector<double> vir(r.stress_virial.begin() + static_cast<long>(first), r.stress_virial.end());
  const std::size_t cut = mser_truncation(wall);
  wall.erase(wall.begin(), wall.begin() + static_cast<long>(cut));
  vir.erase(vir.begin(), vir.begin() + static_cast<long>(cut));
  r.steady_from_strain = r.strain[first + cut];
  r.steady_wall = block_average(wall);
  r.steady_virial = block_average(vir);
  // The period in increments, when lz/gap is a whole number of them.
  if (r.strain.size() > 1 && r.orbit_period_strain > 0) {
    const double inc = r.strain[1] - r.strain[0], p = r.orbit_period_strain / inc;
    const double whole = std::round(p);
    if (whole >= 1 && std::abs(p - whole) < 1e-6 * p)
      r.orbit_wall = orbit_mean(r.stress_wall, first + cut, static_cast<std::size_t>(whole), k_orbit_rel_tol);
  }
}

}  // namespace

OrbitMean orbit_mean(const std::vector<double>& y, std::size_t first, std::size_t period, double rel_tol) {
  OrbitMean o;
  if (period == 0 || first > y.size() || y.size() - first < 2 * period) return o;
  o.period = period;
  const std::size_t n = y.size();
  double scale = 0, dev = 0, sum = 0;
  for (std::size_t k = n - period; k < n; ++k) {
    scale = std::max({scale, std::abs(y[k]), std::abs(y[k - period])});
    dev = std::max(dev, std::abs(y[k] - y[k - period]));
    sum += y[k];
  }
  o.mean = sum / static_cast<double>(period);
  o.deviation = scale > 0 ? dev / scale : 0.0;
  o.periodic = o.deviation <= rel_tol;
  return o;
}

const char* minimiser_name(Minimiser m) {
  switch (m) {
    case Minimiser::lbfgs: return "lbfgs";
    case Minimiser::descent: return "descent";
    case Minimiser::fire: break;
  }
  return "fire";
}

Minimiser parse_minimiser(const std::string& text, const std::string& key) {
  if (text == "fire") return Minimiser::fire;
  if (text == "lbfgs") return Minimiser::lbfgs;
  if (text == "descent") return Minimiser::descent;
  throw InputError(key, text, "", "must be fire, lbfgs or descent");
}

void QuasistaticOptions::validate() const {
  require(strain_increment > 0 && strain_increment <= 0.1, "strain_increment", strain_increment,
          "must be in (0, 0.1] (a quasi-static increment)");
  if (strain) require(*strain > 0, "strain", *strain, "must be > 0");
  if (warmup_strain)
    require(*warmup_strain >= 0 && (!strain || *warmup_strain < *strain), "warmup_strain", *warmup_strain,
            "must be >= 0 and < quasistatic.strain");
  require(force_tol > 0 && force_tol < 1, "force_tol", force_tol, "must be in (0, 1) (a fraction of F0)");
  require(max_iterations > 0, "max_iterations", static_cast<double>(max_iterations), "must be > 0");
  require(lbfgs_memory >= 1 && lbfgs_memory <= 1000, "lbfgs_memory", lbfgs_memory, "must be in [1, 1000]");
  require(descent_step_times_k > 0 && descent_step_times_k <= 0.5, "descent_step_times_k", descent_step_times_k,
          "must be in (0, 0.5] (below the stability limit of a sphere in several contacts)");
  require(dipole_cutoff >= 0, "dipole_cutoff", dipole_cutoff, "must be >= 0 (0: particles.dipole_cutoff)");
  require(dt_max_over_tk > 0 && dt_max_over_tk <= 1, "dt_max_over_tk", dt_max_over_tk, "must be in (0, 1]");
  require(dt_start_over_tk > 0 && dt_start_over_tk <= dt_max_over_tk, "dt_start_over_tk", dt_start_over_tk,
          "must be in (0, dt_max_over_tk]");
  require(max_step_over_radius > 0 && max_step_over_radius <= 0.5, "max_step_over_radius", max_step_over_radius,
          "must be in (0, 0.5]");
}

DemPairLaws<DipoleXShiftedForce> quasistatic_laws(const DemParams& p, double cutoff) {
  return {shifted_dipole_x(p.dipole_pref, cutoff), HertzPair{p.hertz_k, 2.0 * p.radius}, cutoff, p.dipole_pref > 0};
}

QuasistaticState make_quasistatic_state(ShearCell cell, const DemParams& p, double cutoff) {
  QuasistaticState s{std::move(cell), quasistatic_laws(p, cutoff), {}, {}, {}};
  const std::size_t n = s.cell.free.size();
  s.cell.free.v.assign(n, Vec3::Zero());  // quasi-static: no velocities
  s.cell.free.f.assign(n, Vec3::Zero());
  const double two_r = 2.0 * p.radius;
  s.lists = make_pair_lists(std::max(cutoff, two_r), s.cell.walls.size() > 0 ? two_r : 0.0, p.skin);
  return s;
}

void evaluate_forces(QuasistaticState& s) {
  ShearCell& c = s.cell;
  wrap_all(c.free.x, c.box);
  wrap_all(c.walls.x, c.box);
  build_pair_lists(s.lists, c.free, c.walls, c.box);  // rebuilds only the lists that may be stale
  s.sums = compute_pair_forces(s.laws, c.box, c.free, c.walls, s.lists, s.buffers);
}

void apply_strain_increment(QuasistaticState& s, double d_gamma, bool affine) {
  ShearCell& c = s.cell;
  move_walls(c.walls, d_gamma, 1.0);  // gdot dt = d_gamma
  advance_pair_lists(s.lists, d_gamma);
  if (affine)
    for (Vec3& x : c.free.x) x += couette_velocity(x, d_gamma);  // the same profile, over unit time
}

MinimiserOptions quasistatic_minimiser_options(const DemParams& p, const QuasistaticOptions& o) {
  // Contact time scale at a chain's tension, about twice the contact force.
  const double load = 2.0 * p.contact_force;
  const double k_eff = hertz_local_stiffness(hertz_overlap_under_load(load, p.hertz_k), p.hertz_k);
  const double t_k = std::sqrt(p.mass / k_eff);
  MinimiserOptions m;
  m.kind = o.minimiser;
  FireOptions& f = m.fire;
  f.force_tol = o.force_tol * p.contact_force;
  f.max_iterations = o.max_iterations;
  f.dt_max = o.dt_max_over_tk * t_k;
  f.dt_start = o.dt_start_over_tk * t_k;
  f.dt_min = std::min(1e-3 * t_k, f.dt_start);
  f.max_step = o.max_step_over_radius * p.radius;
  f.mass = p.mass;
  LbfgsOptions& l = m.lbfgs;
  l.force_tol = f.force_tol;
  l.max_evaluations = o.max_iterations + 1;
  l.memory = o.lbfgs_memory;
  l.max_step = f.max_step;
  l.initial_scale = 1.0 / k_eff;
  DescentOptions& d = m.descent;
  d.force_tol = f.force_tol;
  d.max_evaluations = o.max_iterations + 1;
  d.step = o.descent_step_times_k / k_eff;
  d.max_step = f.max_step;
  return m;
}

Relaxation relax(QuasistaticState& s, const MinimiserOptions& m, std::size_t increment, double strain) {
  const auto energy = [&s] {
    evaluate_forces(s);
    return s.sums.energy_dipole + s.sums.energy_hertz;
  };
  Relaxation r;
  if (m.kind == Minimiser::lbfgs) {
    const LbfgsResult l = lbfgs_minimize(s.cell.free.x, s.cell.free.f, m.lbfgs, energy);
    r = {l.converged, l.evaluations - 1, l.max_force, l.stop_reason};
  } else if (m.kind == Minimiser::descent) {
    const DescentResult d = descent_minimize(s.cell.free.x, s.cell.free.f, m.descent, energy);
    r = {d.converged, d.evaluations - 1, d.max_force, d.stop_reason};
  } else {
    const FireResult f = fire_minimize(s.cell.free.x, s.cell.free.f, m.fire, energy);
    r = {f.converged, f.iterations, f.max_force, f.stop_reason};
  }
  if (!r.converged)
    throw NumericalError("quasistatic: no minimum at increment " + std::to_string(increment) + " (strain " +
                         format_short(strain) + "): " + minimiser_name(m.kind) + " stopped (" +
                         r.stop_reason + ") after " + std::to_string(r.iterations) + " iterations with max |f| = " +
                         format_short(r.max_force) + " N above the tolerance " + format_short(m.force_tol()) +
                         " N; raise quasistatic.max_iterations or lower quasistatic.strain_increment");
  return r;
}

QuasistaticPoint measure(const QuasistaticState& s) {
  const Box& box = s.cell.box;
  QuasistaticPoint pt;
  pt.stress_wall = wall_shear_stress(s.sums.wall_fz, box);
  pt.stress_virial_magnetic = virial_shear_stress(s.sums.virial_mag_xz, box);
  pt.stress_virial_contact = virial_shear_stress(s.sums.virial_con_xz, box);
  pt.stress_virial = pt.stress_virial_magnetic + pt.stress_virial_contact;
  pt.energy = s.sums.energy_dipole + s.sums.energy_hertz;
  pt.max_force = max_force_norm(s.cell.free.f);
  pt.max_overlap = s.sums.max_overlap;
  return pt;
}

QuasistaticRun::QuasistaticRun(ShearCell cell, const DemParams& p, const QuasistaticOptions& o)
    : o_(o), t0_(std::chrono::steady_clock::now()) {
  o_.validate();
  if (!o_.strain || !o_.warmup_strain)
    throw InputError("quasistatic.strain", "", "", "the total and warm-up strain must be given for a cell built by hand");
  const double rc = o_.dipole_cutoff > 0 ? o_.dipole_cutoff : p.dipole_cutoff;
  o_.dipole_cutoff = rc;
  check_cutoff(rc, p, cell.box, "quasistatic.dipole_cutoff", "");
  minimiser_ = quasistatic_minimiser_options(p, o_);
  minimiser_.fire.validate("quasistatic.fire.");
  minimiser_.lbfgs.validate("quasistatic.lbfgs.");
  minimiser_.descent.validate("quasistatic.descent.");
  s_ = make_quasistatic_state(std::move(cell), p, rc);
  r_.force_scale = p.contact_force;
  r_.force_tol = minimiser_.force_tol();
  r_.dipole_cutoff = rc;
  const Box& box = s_.cell.box;
  r_.stress_scale = static_cast<double>(s_.cell.free.size()) * sphere_volume(p.radius) / box.volume() * k_mu0 *
                    std::pow(p.moment / sphere_volume(p.radius), 2);
  r_.equilibrium_bound = static_cast<double>(s_.cell.free.size()) * 0.5 * box.gap * minimiser_.force_tol() / box.volume();
  r_.orbit_period_strain = box.lz / box.gap;
  count_increments();
}

void QuasistaticRun::count_increments() {
  n_increments_ = first_increment_ + static_cast<std::size_t>(std::ceil(
                                         std::max(0.0, *o_.strain - first_strain_) / o_.strain_increment - 1e-9));
}

double QuasistaticRun::strain_of(std::size_t k) const {
  return first_strain_ + static_cast<double>(k - first_increment_) * o_.strain_increment;
}

QuasistaticPoint QuasistaticRun::step() {
  if (done()) throw std::logic_error("QuasistaticRun::step after the last increment");
  const std::size_t k = next_;
  const double strain = strain_of(k);
  if (k > 0) apply_strain_increment(s_, o_.strain_increment, o_.affine);
  const Relaxation fr = relax(s_, minimiser_, k, strain);
  QuasistaticPoint pt = measure(s_);
  pt.increment = k;
  pt.strain = strain;
  pt.iterations = fr.iterations;
  r_.force_evaluations += fr.iterations + 1;
  record(r_, pt);
  ++next_;
  return pt;
}

double QuasistaticRun::wall_seconds() const {
  return seconds_before_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

QuasistaticResult QuasistaticRun::finish() {
  steady_averages(r_, *o_.warmup_strain);
  r_.list_builds = s_.lists.builds;
  r_.final_cell = std::move(s_.cell);
  r_.wall_seconds = wall_seconds();
  return std::move(r_);
}

void QuasistaticRun::save(ArchiveWriter& out) const {
  out.io(o_.strain_increment, o_.force_tol, static_cast<std::uint8_t>(o_.affine), o_.dipole_cutoff,
         static_cast<std::uint8_t>(o_.minimiser), static_cast<std::uint64_t>(first_increment_), first_strain_);
  serialize(out, *this);
  out.put(wall_seconds());
}

void QuasistaticRun::load(ArchiveReader& in, bool branch) {
  double increment = 0, tol = 0, cutoff = 0;
  std::uint8_t affine = 0, minimiser = 0;
  std::uint64_t first_increment = 0;
  double first_strain = 0;
  in.io(increment, tol, affine, cutoff, minimiser, first_increment, first_strain);
  const auto refuse = [&](const std::string& key, const std::string& saved, const std::string& now) {
    throw NumericalError("checkpoint " + in.path() + " was written with quasistatic." + key + " = " + saved +
                         ", this run asks for " + now + ": start a new run (another --out) or resume with the same value");
  };
  if (increment != o_.strain_increment && !branch)
    refuse("strain_increment", format_short(increment), format_short(o_.strain_increment));
  if (tol != o_.force_tol && !branch) refuse("force_tol", format_short(tol), format_short(o_.force_tol));
  if ((affine != 0) != o_.affine) refuse("affine", affine ? "on" : "off", o_.affine ? "on" : "off");
  if (minimiser > static_cast<std::uint8_t>(Minimiser::descent))
    throw NumericalError("checkpoint " + in.path() + " is damaged: minimiser code " + std::to_string(minimiser));
  if (static_cast<Minimiser>(minimiser) != o_.minimiser && !branch)
    refuse("minimiser", minimiser_name(static_cast<Minimiser>(minimiser)), minimiser_name(o_.minimiser));
  if (cutoff != o_.dipole_cutoff) refuse("dipole_cutoff", format_short(cutoff) + " m", format_short(o_.dipole_cutoff) + " m");
  const std::size_t n_free = s_.cell.free.size(), n_wall = s_.cell.walls.size();
  serialize(in, *this);
  in.get(seconds_before_);
  if (branch) seconds_before_ = 0;
  t0_ = std::chrono::steady_clock::now();
  if (s_.cell.free.x.size() != n_free || s_.cell.walls.x.size() != n_wall)
    throw NumericalError("checkpoint " + in.path() + " holds " + std::to_string(s_.cell.free.x.size()) + " free and " +
                         std::to_string(s_.cell.walls.x.size()) + " wall spheres, the scene builds " +
                         std::to_string(n_free) + " and " + std::to_string(n_wall));
  if (r_.strain.size() != next_)
    throw NumericalError("checkpoint " + in.path() + " is inconsistent: " + std::to_string(r_.strain.size()) +
                         " minima recorded for " + std::to_string(next_) + " increments");
  if (r_.strain.empty())
    throw NumericalError("checkpoint " + in.path() + " holds no minimum: it cannot be resumed or branched from");
  // A branch goes on from the parent's last minimum with its own increment
  // (the parent's strains before it stay as they were); a plain load keeps
  // the saved numbering.
  first_increment_ = branch ? next_ : static_cast<std::size_t>(first_increment);
  first_strain_ = branch ? r_.strain.back() + o_.strain_increment : first_strain;
  if (branch && *o_.strain < first_strain_ - 1e-9 * o_.strain_increment)
    throw NumericalError("checkpoint " + in.path() + " ends at strain " + format_short(r_.strain.back()) +
                         ": a branch from it needs quasistatic.strain >= " + format_short(first_strain_) +
                         " (one increment further), not " + format_short(*o_.strain));
  count_increments();
}

namespace {
QuasistaticResult run_to_end(QuasistaticRun& run, const QuasistaticObserver& observer) {
  while (!run.done()) {
    const QuasistaticPoint pt = run.step();
    if (observer) observer(pt);
  }
  return run.finish();
}
}  // namespace

QuasistaticResult run_quasistatic(ShearCell cell, const DemParams& p, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer) {
  QuasistaticRun run(std::move(cell), p, o);
  return run_to_end(run, observer);
}

QuasistaticRun quasistatic_run(const LoadedScene& scene, const QuasistaticOptions& o, const std::string& start_from) {
  const SceneConfig& c = scene.config;
  if (!(c.magnetization > 0))
    throw InputError("particles.magnetization", format_short(c.magnetization) + " A/m", scene.locate("particles.magnetization"),
                     "quasi-static shear needs magnetic particles (its force tolerance is relative to the dipole "
                     "contact force)");
  use_scene_threads(c);  // numerics.threads, as mrf run
  QuasistaticOptions opt = o;
  if (!opt.strain) opt.strain = c.strain;
  if (!opt.warmup_strain) opt.warmup_strain = c.warmup_strain;
  ShearCell cell = build_shear_cell(c, scene.locate("particles.volume_fraction"));
  if (!start_from.empty()) {
    Frame f = read_last_frame(start_from, "--start-from");
    if (f.free.size() != cell.free.size() || f.walls.size() != cell.walls.size())
      throw InputError("--start-from", start_from, "",
                       "its last frame holds " + std::to_string(f.free.size()) + " free and " +
                           std::to_string(f.walls.size()) + " wall spheres, the scene builds " +
                           std::to_string(cell.free.size()) + " and " + std::to_string(cell.walls.size()) +
                           " (a frame of another scene?)");
    const double half = 0.5 * cell.box.gap;
    for (std::size_t i = 0; i < f.free.size(); ++i)
      if (std::abs(f.free[i].x()) > half)
        throw InputError("--start-from", start_from, "",
                         "free sphere " + std::to_string(i) + " lies outside the gap (x = " + format_short(f.free[i].x()) +
                             " m, |x| must be <= " + format_short(half) + " m)");
    cell.free.x = std::move(f.free);
    cell.walls.x = std::move(f.walls);
  }
  return QuasistaticRun(std::move(cell), dem_params(c), opt);
}

QuasistaticResult run_quasistatic(const LoadedScene& scene, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer) {
  QuasistaticRun run = quasistatic_run(scene, o);
  return run_to_end(run, observer);
}

}  // namespace mrf
