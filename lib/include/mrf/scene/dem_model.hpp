// The one-way DEM-Stokes model (`dem_stokes`): free magnetic spheres, wall
// spheres (optional), imposed Couette flow, and one of three integrators:
//  verlet_exp  exponential velocity Verlet: drag exact over the step,
//              forces linear in time (integrate/steps.hpp)
//  overdamped  v = u(x) + F/gamma, x += v dt   (inertialess, first order)
//  implicit    inertialess, Hertz contacts implicit, dipole and flow explicit
//              (integrate/implicit_stepper.hpp); the step size is chosen
//              from a local error estimate, up to the dt given.
#pragma once
#include <limits>
#include <optional>

#include "mrf/integrate/implicit_stepper.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

class DemModel {
 public:
  DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt);

  // One (accepted) step. For the implicit scheme dt() is the step just taken
  // and the next one is chosen by the error control, at most max_dt().
  void step();
  void set_implicit_options(const ImplicitOptions& o) { implicit_->set_options(o); }
  // The implicit scheme shortens the step that would pass t (s) to end on it.
  void set_stop_time(double t) { implicit_->set_stop_time(t); }
  const ImplicitCounters& implicit_counters() const { return implicit_->counters(); }
  double max_dt() const { return implicit_ ? implicit_->max_dt() : dt_; }

  const ShearCell& cell() const { return cell_; }
  const DemParams& params() const { return p_; }
  const PairSums& sums() const { return sums_; }
  const DemPairLists& lists() const { return lists_; }
  IntegratorId scheme() const { return scheme_; }
  double dt() const { return implicit_ ? implicit_->dt() : dt_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  // Largest overlap the chosen dt keeps stable (m); exceeding it stops the run.
  double overlap_limit() const { return overlap_limit_; }

  // Checkpoint: the whole dynamic state (particles, walls, forces, pair
  // lists, clock), so that a restored model continues bit for bit
  // (scene/dem_checkpoint.cpp). load() expects a model built from the same scene.
  void save(ArchiveWriter& out) const;
  void load(ArchiveReader& in);

 private:
  void update_forces();
  void implicit_step();
  void check_finite_positions() const;  // before binning: the cell list needs finite coordinates
  void check_finite() const;

  ShearCell cell_;
  DemParams p_;
  IntegratorId scheme_;
  double dt_;
  DemPairLists lists_;
  PairSums sums_;
  ForceBuffers buffers_;
  std::vector<Vec3> w_;  // verlet_exp: drift velocities of the current step (scratch)
  double time_ = 0;
  long steps_ = 0;
  double overlap_limit_;
  std::optional<ImplicitStepper> implicit_;
  ImplicitDrift drift_;  // implicit: explicit part of the current step (scratch)
};

// The DEM part of a checkpoint, shared by DemModel and CoupledModel: free
// particles (x, v, f), wall positions and the Verlet lists as built (their
// reference positions decide the next rebuild, their order the round-off).
// load_dem_state throws NumericalError when the particle counts differ.
void save_dem_state(ArchiveWriter& out, const ShearCell& cell, const DemPairLists& lists);
void load_dem_state(ArchiveReader& in, ShearCell& cell, DemPairLists& lists);

}  // namespace mrf
