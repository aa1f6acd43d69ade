// The one place where a scene becomes a model: the integrator and time step
// chosen from the stability limits (and printed), each part's own parameters
// derived once, and the fields of summary.json that are known before the
// run. `mrf run`, the tests and the benchmarks all build through it.
#pragma once
#include <memory>
#include <vector>

#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/integrate/limit.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/coupled_model.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/model.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {

struct TimeStepChoice {
  IntegratorId scheme;
  double dt;                            // s
  std::vector<StabilityLimit> limits;   // of the chosen scheme
  std::vector<StabilityLimit> other;    // of the scheme not chosen (for the printout)
};

// Model 1. auto: the inertialess implicit scheme where St <= the bound above
// and its step bound is k_implicit_preference times the best explicit one;
// verlet_exp where St is above it; dt = dt_safety x the smallest limit (the
// implicit scheme: the limit itself, its error control picks the steps). A
// user dt above the smallest limit is an InputError on numerics.dt.
TimeStepChoice choose_time_step(const LoadedScene& scene, const DemParams& p);

// The step bound of the error-controlled schemes from the averaging window:
// at least 64 steps in drive.strain - drive.warmup_strain, so that block
// averaging has its rows (a sampling bound, added after the scheme is chosen).
StabilityLimit window_limit(const SceneConfig& c);

struct CoupledTimeStep {
  CoupledStepping stepping;
  std::vector<StabilityLimit> dem_limits;    // of the DEM step (inertial: sub-step)
  std::vector<StabilityLimit> fluid_limits;  // of the SPH step (CFL, viscous with superficial density)
};

// Models 2 and 3. Inertial (integrator verlet_exp, or auto above the Stokes
// bound): dt_fluid = dt_safety x the smallest SPH limit (or numerics.dt,
// refused above it), split into the fewest DEM sub-steps below dt_safety x
// the smallest DEM limit. Inertialess (implicit, or auto at or below the
// bound): error-controlled DEM steps up to the implicit scheme's limits, SPH
// sub-steps of dt_safety x the smallest SPH limit, the viscosity implicit
// where the viscous limit is k_implicit_viscosity_gain below the CFL one.
// eps_min: porosity the viscous limit is designed for.
CoupledTimeStep choose_coupled_time_step(const LoadedScene& scene, const DemParams& p, const FluidCell& fluid,
                                         double eps_min);
// Implicit SPH viscosity pays only where it lengthens the sub-step well
// beyond the explicit one: on the small scene at Mn = 1e-2 (viscous limit
// 2.2x below CFL) it was 12 % slower (0.72 against 0.64 s per strain unit);
// at gdot = 2000 1/s the ratio is 8.7. Not measured in between.
inline constexpr double k_implicit_viscosity_gain = 4.0;

CoupledDrag coupled_drag(ModelId m);

struct BuiltModel {
  std::unique_ptr<Model> model;
  RunSummary summary;  // the fields known before the run
  long planned_steps;  // fixed steps to the end, or for adaptive steps the number at the largest step
};

// Builds the model of a scene: DemModel (dem_stokes), CoupledModel
// (demsph_* with particles) or FluidOnlyModel (demsph_* without,
// scene/fluid_only.hpp). Prints the start-up table unless quiet.
BuiltModel build_model(const LoadedScene& scene, bool quiet = true);

}  // namespace mrf
