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
#include "mrf/scene/model.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

class DemModel final : public Model {
 public:
  DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt);

  // One (accepted) step. For the implicit scheme dt() is the step just taken
  // and the next one is chosen by the error control, at most max_dt().
  void step() override;
  void set_implicit_options(const ImplicitOptions& o) { implicit_->set_options(o); }
  // The implicit scheme shortens the step that would pass t (s) to end on it.
  void set_stop_time(double t) override {
    if (implicit_) implicit_->set_stop_time(t);
  }
  bool adaptive() const override { return implicit_.has_value(); }
  StepSample sample() const override;
  void finish(RunSummary& s) const override;
  const ImplicitCounters& implicit_counters() const { return implicit_->counters(); }
  double max_dt() const { return implicit_ ? implicit_->max_dt() : dt_; }
  const ImplicitStepper* implicit() const { return implicit_ ? &*implicit_ : nullptr; }

  const ShearCell& cell() const override { return cell_; }
  const DemParams& params() const { return p_; }
  const PairSums& sums() const { return sums_; }
  const DemPairLists& lists() const override { return lists_; }
  IntegratorId scheme() const { return scheme_; }
  double dt() const override { return implicit_ ? implicit_->dt() : dt_; }
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  // Largest overlap the chosen dt keeps stable (m); exceeding it stops the run.
  double overlap_limit() const { return overlap_limit_; }

  // Checkpoint: the whole dynamic state (particles, walls, forces, pair
  // lists, clock), so that a restored model continues bit for bit
  // (scene/dem_checkpoint.cpp). load() expects a model built from the same scene.
  void save(ArchiveWriter& out) const override { serialize(out, *this); }
  void load(ArchiveReader& in) override;

 private:
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& m) {
    serialize_dem_state(ar, m.cell_, m.lists_);
    ar.io(m.sums_, m.time_, m.steps_);
    if (m.implicit_) ar.io(*m.implicit_);  // the step just taken, the next try, the work so far, the history
  }
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

// Verlet lists of a DEM scene: free-free pairs within the dipole cut-off (or
// contact), free-wall pairs within contact (`walls`), each with the reach of
// the scheme (the implicit scheme's contact candidates lie within 2R + the
// contact margin) and its skin; near_reach (m) is that of the implicit
// scheme's near list of contact candidates.
DemPairLists dem_pair_lists(const DemParams& p, const Box& box, bool implicit, bool walls, double& near_reach);
ImplicitContactParams implicit_contact_params(const DemParams& p);

// The DEM part of a checkpoint, shared by DemModel and CoupledModel: free
// particles (x, v, f), wall positions and the Verlet lists as built; one
// field list for both directions (io/archive.hpp).
template <class Archive, class Cell, class Lists>
void serialize_dem_state(Archive& ar, Cell& cell, Lists& lists) {
  ar.io(cell.free.x, cell.free.v, cell.free.f, cell.walls.x, lists);
}
// After a load: NumericalError unless the particle counts are the scene's.
void check_dem_state(const ShearCell& cell, std::size_t n_free, std::size_t n_wall);

}  // namespace mrf
