// `mrf run` for the coupled models demsph_stokes and demsph_dd with
// particles (scene/coupled_model.hpp): time steps from the DEM and SPH
// limits, multi-rate loop, stress series and summary.json (the keys of
// model 1 plus the model extras in RunSummary::extra).
#pragma once
#include <string>
#include <vector>

#include "mrf/scene/coupled_model.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {

struct CoupledTimeStep {
  double dt_fluid = 0;                      // s
  int substeps = 1;                         // DEM sub-steps per fluid step
  std::vector<StabilityLimit> dem_limits;   // verlet_exp limits of the DEM sub-step
  std::vector<StabilityLimit> fluid_limits; // SPH limits (CFL, viscous with superficial density)
};

// dt_fluid = dt_safety x smallest SPH limit (or numerics.dt, refused above
// it), split into the fewest DEM sub-steps that keep each below dt_safety x
// the smallest DEM limit. No limit depends on the drag relaxation time.
CoupledTimeStep choose_coupled_time_step(const LoadedScene& scene, const DemParams& p, const FluidCell& fluid,
                                         double eps_min);

CoupledDrag coupled_drag(ModelId m);

RunSummary run_coupled_scene(const LoadedScene& scene, const RunOptions& opt);

}  // namespace mrf
