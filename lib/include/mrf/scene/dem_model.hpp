// The one-way DEM-Stokes model (`dem_stokes`): free magnetic spheres, wall
// spheres (optional), imposed Couette flow, and one of two integrators:
//  verlet_exp  exponential velocity Verlet: drag exact over the step,
//              forces linear in time (integrate/steps.hpp)
//  overdamped  v = u(x) + F/gamma, x += v dt   (inertialess, first order)
#pragma once
#include "mrf/integrate/stability.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

class DemModel {
 public:
  DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt);

  void step();

  const ShearCell& cell() const { return cell_; }
  const DemParams& params() const { return p_; }
  const PairSums& sums() const { return sums_; }
  const DemPairLists& lists() const { return lists_; }
  IntegratorId scheme() const { return scheme_; }
  double dt() const { return dt_; }
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
  void check_finite_positions() const;  // before binning: the cell list needs finite coordinates
  void check_finite() const;

  ShearCell cell_;
  DemParams p_;
  IntegratorId scheme_;
  double dt_;
  DemPairLists lists_;
  PairSums sums_;
  ForceBuffers buffers_;
  std::vector<Vec3> w_;  // drift velocities of the current step (scratch)
  double time_ = 0;
  long steps_ = 0;
  double overlap_limit_;
};

}  // namespace mrf
