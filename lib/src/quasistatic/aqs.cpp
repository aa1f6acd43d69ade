#include "mrf/quasistatic/aqs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/integrate/steps.hpp"
#include "mrf/observe/steady_state.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/dem_params.hpp"

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

void QuasistaticOptions::validate() const {
  require(strain_increment > 0 && strain_increment <= 0.1, "strain_increment", strain_increment,
          "must be in (0, 0.1] (a quasi-static increment)");
  if (strain) require(*strain > 0, "strain", *strain, "must be > 0");
  if (warmup_strain)
    require(*warmup_strain >= 0 && (!strain || *warmup_strain < *strain), "warmup_strain", *warmup_strain,
            "must be >= 0 and < quasistatic.strain");
  require(force_tol > 0 && force_tol < 1, "force_tol", force_tol, "must be in (0, 1) (a fraction of F0)");
  require(max_iterations > 0, "max_iterations", static_cast<double>(max_iterations), "must be > 0");
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

FireOptions quasistatic_fire_options(const DemParams& p, const QuasistaticOptions& o) {
  // Contact time scale at a chain's tension, about twice the contact force.
  const double load = 2.0 * p.contact_force;
  const double k_eff = hertz_local_stiffness(hertz_overlap_under_load(load, p.hertz_k), p.hertz_k);
  const double t_k = std::sqrt(p.mass / k_eff);
  FireOptions f;
  f.force_tol = o.force_tol * p.contact_force;
  f.max_iterations = o.max_iterations;
  f.dt_max = o.dt_max_over_tk * t_k;
  f.dt_start = o.dt_start_over_tk * t_k;
  f.dt_min = std::min(1e-3 * t_k, f.dt_start);
  f.max_step = o.max_step_over_radius * p.radius;
  f.mass = p.mass;
  return f;
}

FireResult relax(QuasistaticState& s, const FireOptions& fire, std::size_t increment, double strain) {
  const FireResult r = fire_minimize(s.cell.free.x, s.cell.free.f, fire, [&s] {
    evaluate_forces(s);
    return s.sums.energy_dipole + s.sums.energy_hertz;
  });
  if (!r.converged)
    throw NumericalError("quasistatic: no minimum at increment " + std::to_string(increment) + " (strain " +
                         format_short(strain) + "): FIRE stopped (" + r.stop_reason + ") after " +
                         std::to_string(r.iterations) + " iterations with max |f| = " + format_short(r.max_force) +
                         " N above the tolerance " + format_short(fire.force_tol) +
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

QuasistaticResult run_quasistatic(ShearCell cell, const DemParams& p, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer) {
  o.validate();
  if (!o.strain || !o.warmup_strain)
    throw InputError("quasistatic.strain", "", "", "the total and warm-up strain must be given for a cell built by hand");
  const auto t0 = std::chrono::steady_clock::now();
  const double rc = o.dipole_cutoff > 0 ? o.dipole_cutoff : p.dipole_cutoff;
  check_cutoff(rc, p, cell.box, "quasistatic.dipole_cutoff", "");
  const FireOptions fire = quasistatic_fire_options(p, o);
  fire.validate("quasistatic.fire.");
  QuasistaticState s = make_quasistatic_state(std::move(cell), p, rc);
  QuasistaticResult r;
  r.force_scale = p.contact_force;
  r.force_tol = fire.force_tol;
  r.dipole_cutoff = rc;
  const Box& box = s.cell.box;
  r.stress_scale = static_cast<double>(s.cell.free.size()) * sphere_volume(p.radius) / box.volume() * k_mu0 *
                   std::pow(p.moment / sphere_volume(p.radius), 2);
  r.equilibrium_bound = static_cast<double>(s.cell.free.size()) * 0.5 * box.gap * fire.force_tol / box.volume();
  r.orbit_period_strain = box.lz / box.gap;
  const auto n_inc = static_cast<std::size_t>(std::ceil(*o.strain / o.strain_increment - 1e-9));
  for (std::size_t k = 0; k <= n_inc; ++k) {
    const double strain = static_cast<double>(k) * o.strain_increment;
    if (k > 0) apply_strain_increment(s, o.strain_increment, o.affine);
    const FireResult fr = relax(s, fire, k, strain);
    QuasistaticPoint pt = measure(s);
    pt.increment = k;
    pt.strain = strain;
    pt.iterations = fr.iterations;
    r.force_evaluations += fr.iterations + 1;
    record(r, pt);
    if (observer) observer(pt);
  }
  steady_averages(r, *o.warmup_strain);
  r.list_builds = s.lists.builds;
  r.final_cell = std::move(s.cell);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

QuasistaticResult run_quasistatic(const LoadedScene& scene, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer) {
  const SceneConfig& c = scene.config;
  if (!(c.magnetization > 0))
    throw InputError("particles.magnetization", format_short(c.magnetization) + " A/m", scene.locate("particles.magnetization"),
                     "quasi-static shear needs magnetic particles (its force tolerance is relative to the dipole "
                     "contact force)");
  const DemParams p = dem_params(c);
  QuasistaticOptions opt = o;
  if (!opt.strain) opt.strain = c.strain;
  if (!opt.warmup_strain) opt.warmup_strain = c.warmup_strain;
  ShearCell cell = build_shear_cell(c, scene.locate("particles.volume_fraction"));
  return run_quasistatic(std::move(cell), p, opt, observer);
}

}  // namespace mrf
