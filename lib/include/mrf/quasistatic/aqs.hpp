// Athermal quasi-static shear (AQS) of the shear cell: the rate-independent
// limit Mn -> 0 of the DEM model without time steps (issue 17, DESIGN.md).
//
// Each increment: the wall spheres are displaced by +-(gap/2) d_gamma along z
// (the wall motion of integrate/steps.hpp, move_walls, with gdot dt = d_gamma),
// the free particles optionally by the affine field d_gamma x (default on:
// the standard AQS start point, it removes most of the elastic relaxation
// the minimiser would otherwise do), then the free particles are relaxed to
// a local minimum of the dipole + Hertz energy by FIRE 2.0
// (quasistatic/fire.hpp; the default) or L-BFGS (quasistatic/lbfgs.hpp;
// quasistatic.minimiser, reports/quasistatic/minimiser.md compares them)
// until the largest force on a free particle is below
// force_tol F0, F0 = (pi/6) mu0 R^2 M^2 the head-to-tail dipole force at
// contact (REFERENCE TEST 1.1). The dipole law is the shifted-force form of
// quasistatic/shifted_dipole.hpp (continuous energy and force at the
// cut-off); Hertz as forces/hertz.hpp, energy (2/5) k h^{5/2}. The pair loop
// is the scene's (scene/dem_forces.hpp) with that dipole evaluator.
//
// At each minimum the wall stress and the virial stress (observe/stress.hpp)
// are taken, in Pa. In static equilibrium they agree: the virial identity
// (verification/observe/test_stress.cpp) gives wall - virial =
// (1/V) sum_i x_i f_i,z, bounded by N (gap/2) force_tol / V at an accepted
// minimum. A minimisation that does not converge is a NumericalError: the
// run never continues from a non-minimum.
#pragma once
#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mrf/io/archive.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/observe/block_average.hpp"
#include "mrf/params.hpp"
#include "mrf/quasistatic/descent.hpp"
#include "mrf/quasistatic/fire.hpp"
#include "mrf/quasistatic/lbfgs.hpp"
#include "mrf/quasistatic/shifted_dipole.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

enum class Minimiser { fire, lbfgs, descent };
const char* minimiser_name(Minimiser m);  // "fire", "lbfgs", "descent"
// InputError naming `key` and the accepted names on anything else.
Minimiser parse_minimiser(const std::string& text, const std::string& key);

struct QuasistaticOptions {
  Minimiser minimiser = Minimiser::fire;
  double strain_increment = 1e-3;      // d_gamma per increment
  std::optional<double> strain;        // total strain; default the scene's drive.strain
  std::optional<double> warmup_strain; // excluded from the steady mean; default drive.warmup_strain
  bool affine = true;                  // affine displacement d_gamma x of the free particles
  double force_tol = 1e-6;             // accepted minimum: max |f_i| < force_tol F0
  long max_iterations = 200000;        // force evaluations allowed per minimisation after the first
  int lbfgs_memory = 10;               // L-BFGS correction pairs
  double descent_step_times_k = 0.1;   // steepest descent: h k_eff (the Euler step of the gradient flow)
  double dipole_cutoff = 0;            // r_c of the shifted-force law (m); 0 = particles.dipole_cutoff
  // FIRE step sizes relative to the contact time scale t_k = sqrt(m_p / k_eff),
  // k_eff = dF/dh of Hertz at twice the contact force (a chain's tension):
  double dt_max_over_tk = 0.4;         // semi-implicit Euler is stable below ~0.58 t_k with 6 contacts
  double dt_start_over_tk = 0.04;
  double max_step_over_radius = 0.05;  // largest displacement of one particle per iteration / R (both minimisers)

  // InputError naming quasistatic.<field> on a bad value.
  void validate() const;
};

// One accepted minimum.
struct QuasistaticPoint {
  std::size_t increment = 0;  // 0: the minimum of the initial configuration
  double strain = 0;
  double stress_wall = 0;            // Pa, observe/stress.hpp wall_shear_stress
  double stress_virial = 0;          // Pa, magnetic + contact
  double stress_virial_magnetic = 0; // Pa
  double stress_virial_contact = 0;  // Pa
  double energy = 0;                 // J, shifted dipole + Hertz
  double max_force = 0;              // N, max |f_i| over the free particles
  double max_overlap = 0;            // m
  long iterations = 0;               // force evaluations of this minimisation after the first
};

// A periodic orbit in a series sampled at equal strain steps: the walls
// return to an image of their start every lz/gap of strain, and a
// quasi-static run can then repeat itself exactly (reports/quasistatic/).
struct OrbitMean {
  bool periodic = false;  // the last `period` samples repeat the `period` before them within rel_tol
  std::size_t period = 0; // samples; 0 when the series is shorter than two periods
  double mean = 0;        // mean over the last whole period (the orbit's mean when periodic)
  double deviation = 0;   // largest |y[k] - y[k - period]| over the last period, / max |y|
};
// Checks y[first..] for a period of `period` samples (relative tolerance
// rel_tol of the largest |y|) and returns the mean of its last period.
OrbitMean orbit_mean(const std::vector<double>& y, std::size_t first, std::size_t period, double rel_tol);

struct QuasistaticResult {
  // One entry per accepted minimum, increment 0 first.
  std::vector<double> strain, stress_wall, stress_virial, stress_virial_magnetic, stress_virial_contact, energy,
      max_force, max_overlap;
  std::vector<long> iterations;
  // Steady flow: the points with strain >= warmup, less the MSER-5
  // transient (observe/steady_state.hpp), block-averaged over strain.
  double steady_from_strain = 0;
  BlockAverage steady_wall, steady_virial;  // Pa
  // The wall stress over the last period lz/gap of the steady part: when
  // the run has settled on a periodic orbit (exactly repeating minima) the
  // block error says nothing, and this mean is the run's value.
  double orbit_period_strain = 0;  // lz/gap
  OrbitMean orbit_wall;
  double force_scale = 0;        // F0 (N)
  double force_tol = 0;          // N
  double stress_scale = 0;       // phi mu0 M^2 (Pa), for reports
  double dipole_cutoff = 0;      // m
  double equilibrium_bound = 0;  // N (gap/2) force_tol / V (Pa): |wall - virial| bound at a minimum
  long force_evaluations = 0;
  long list_builds = 0;
  double wall_seconds = 0;
  ShearCell final_cell;          // the last minimum
};

// The state the minimiser works on: the cell, the laws, their pair lists.
struct QuasistaticState {
  ShearCell cell;
  DemPairLaws<DipoleXShiftedForce> laws;
  DemPairLists lists;
  ForceBuffers buffers;
  PairSums sums;  // of the last force evaluation
};

// The laws of DemParams with the shifted-force dipole at `cutoff` (m).
DemPairLaws<DipoleXShiftedForce> quasistatic_laws(const DemParams& p, double cutoff);
QuasistaticState make_quasistatic_state(ShearCell cell, const DemParams& p, double cutoff);

// Forces on the free particles at their current positions (wraps y, z and
// rebuilds stale lists); sums kept in state.sums.
void evaluate_forces(QuasistaticState& s);

// Walls by +-(gap/2) d_gamma in z; with `affine`, each free particle by d_gamma x.
void apply_strain_increment(QuasistaticState& s, double d_gamma, bool affine);

// The minimiser of a scene and its settings: tolerances and steps from
// DemParams (see the fields above). L-BFGS takes the same tolerance, budget
// and step cap as FIRE, and 1/k_eff (the inverse contact stiffness FIRE's
// steps are scaled by) as its first inverse-Hessian guess.
struct MinimiserOptions {
  Minimiser kind = Minimiser::fire;
  FireOptions fire;
  LbfgsOptions lbfgs;
  DescentOptions descent;
  double force_tol() const { return fire.force_tol; }  // N, the same for both
};
MinimiserOptions quasistatic_minimiser_options(const DemParams& p, const QuasistaticOptions& o);

// What one minimisation did, either minimiser.
struct Relaxation {
  bool converged = false;
  long iterations = 0;      // force evaluations after the first (FIRE: its MD steps)
  double max_force = 0;     // N
  std::string stop_reason;
};

// Relax to a minimum; NumericalError (naming increment, strain, iterations,
// max |f| and the tolerance) if the minimiser stops without convergence.
Relaxation relax(QuasistaticState& s, const MinimiserOptions& m, std::size_t increment, double strain);

// The observables of the current (relaxed) state.
QuasistaticPoint measure(const QuasistaticState& s);

// Called at every accepted minimum (progress, frames); may be empty.
using QuasistaticObserver = std::function<void(const QuasistaticPoint&)>;

// One run, one accepted minimum at a time: what run_quasistatic loops over,
// and what a run of hours checkpoints between minima. Between minima the
// whole state is the cell (free and wall positions), its pair lists and the
// series so far: FIRE starts afresh at every increment, so a run restored by
// load() continues bit for bit (verification/quasistatic/test_aqs.cpp).
class QuasistaticRun {
 public:
  // `strain` and `warmup_strain` of the options must be set.
  QuasistaticRun(ShearCell cell, const DemParams& p, const QuasistaticOptions& o);
  bool done() const { return next_ > n_increments_; }
  std::size_t next_increment() const { return next_; }
  std::size_t increments() const { return n_increments_; }  // the last increment; 0 is the initial minimum
  const QuasistaticOptions& options() const { return o_; }  // as run: the cut-off resolved
  // Applies the next increment (none for the initial minimum), relaxes to a
  // minimum and records it; NumericalError if the minimiser does not converge.
  QuasistaticPoint step();
  const QuasistaticResult& series() const { return r_; }  // the minima so far
  double wall_seconds() const;  // so far, over every session of a resumed run
  // The steady means over the minima so far and the final cell; the run is spent.
  QuasistaticResult finish();

  // The increment, tolerance, affine start, cut-off and minimiser are part
  // of the state: load() refuses (NumericalError naming the option and both
  // values) a checkpoint written with others. The total strain may differ:
  // a run is extended by resuming it with a larger one.
  // branch: a new run from another run's checkpoint, whose force tolerance,
  // minimiser and strain increment may differ (affine start and cut-off may
  // not): its minima so far are the other run's, each later one with this
  // run's settings, so two tolerances, minimisers or increments are
  // compared along one path from the same minimum; its wall time starts at
  // 0. After a branch at another increment the minima are not equally
  // spaced in strain across the branch point.
  void save(ArchiveWriter& out) const;
  void load(ArchiveReader& in, bool branch = false);

 private:
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& q) {
    auto& r = q.r_;  // const for the writer: one field list for both directions
    ar.io(q.s_.cell.free.x, q.s_.cell.walls.x, q.s_.lists, q.next_, r.strain,
          r.stress_wall, r.stress_virial, r.stress_virial_magnetic, r.stress_virial_contact, r.energy, r.max_force,
          r.max_overlap, r.iterations, r.force_evaluations);
  }
  QuasistaticState s_;
  QuasistaticOptions o_;
  MinimiserOptions minimiser_;
  QuasistaticResult r_;
  std::size_t n_increments_ = 0, next_ = 0;
  // Strain of increment k: first_strain_ + (k - first_increment_) d; (0, 0)
  // unless the run is a branch at another increment d (then the branch
  // point: the parent's last increment + 1, and its strain + d).
  std::size_t first_increment_ = 0;
  double first_strain_ = 0;
  double strain_of(std::size_t k) const;
  void count_increments();
  double seconds_before_ = 0;  // wall seconds of earlier sessions (resumed runs)
  std::chrono::steady_clock::time_point t0_;
};

// The run of a scene: the cell of build_shear_cell(scene) (the builder
// every model uses), DemParams from dem_params(scene.config), the strain
// and warm-up of drive.* unless the options set them; a magnetisation of 0
// is refused (no force scale), as is a cut-off that breaks the minimum image.
// start_from: a frames.xyz of `mrf run` on the same scene (output.frames);
// its last frame replaces the built positions of the free and wall spheres,
// so the first minimum is relaxed from a structure made by flow rather than
// from the random packing. InputError (key --start-from) when its counts
// differ from the scene's.
QuasistaticRun quasistatic_run(const LoadedScene& scene, const QuasistaticOptions& o,
                               const std::string& start_from = "");

// The whole run on a cell built by hand (tests) or from a scene. `strain` and
// `warmup_strain` of the options must be set for the first form.
QuasistaticResult run_quasistatic(ShearCell cell, const DemParams& p, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer = {});
QuasistaticResult run_quasistatic(const LoadedScene& scene, const QuasistaticOptions& o,
                                  const QuasistaticObserver& observer = {});

}  // namespace mrf
