// Fluid-only start-up Couette run of the SPH carrier in the shear cell, from
// a scene (model demsph_*, volume_fraction = 0): the third Model that
// `mrf run` builds (build_model) and the end-to-end check of the fluid
// solver.
#pragma once
#include <cstdint>
#include <vector>

#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/wcsph.hpp"
#include "mrf/scene/config.hpp"
#include "mrf/scene/model.hpp"

namespace mrf {

// Fluid parameters of a scene: [fluid] viscosity, density, sph_spacing,
// sound_speed and [drive] shear_rate (no body force).
FluidParams fluid_params_from_scene(const SceneConfig& cfg);

struct CouetteSphResult {
  double time = 0;                   // simulated time reached (s)
  double shear_stress = 0;           // tau from the wall forces at `time` (Pa)
  double analytic_stress = 0;        // eta du/dx at the walls, start-up series at `time` (Pa)
  double steady_stress = 0;          // eta gdot (Pa)
  double profile_error = 0;          // relative L2 error of v_z vs the start-up series (1)
  double mean_density_error = 0;     // mean |rho/rho0 - 1| at the end (1)
  double max_density_deviation = 0;  // largest |rho/rho0 - 1| seen during the run (1)
  double reynolds = 0;               // rho gdot gap^2 / eta (1)
  double sound_speed = 0;            // c0 used (m/s)
  bool implicit_viscosity = false;
  double dt = 0;                     // s
  std::int64_t steps = 0;
  std::vector<StabilityLimit> limits;  // of the scheme used, at start
  double wall_seconds = 0;
  std::size_t n_fluid = 0, n_wall = 0;
};

// The SPH shear cell from rest, fixed steps: explicit, or the viscosity by
// backward Euler. Its stress is the wall stress of the fluid; finish()
// reports the value at the end (a start-up transient has no steady window)
// beside the start-up series of REFERENCE §5 at that time.
class FluidOnlyModel final : public Model {
 public:
  FluidOnlyModel(FluidCell cell, bool implicit_viscosity, double dt);
  void step() override;
  double time() const override { return fluid_.time; }
  double dt() const override { return dt_; }
  long steps() const override { return static_cast<long>(fluid_.steps); }
  bool adaptive() const override { return false; }
  void set_stop_time(double) override {}
  StepSample sample() const override;
  const ShearCell& cell() const override { return no_particles_; }
  const DemPairLists& lists() const override { return no_lists_; }
  void save(ArchiveWriter& out) const override { serialize(out, *this); }
  void load(ArchiveReader& in) override;
  void finish(RunSummary& s) const override;
  const FluidCell& fluid() const { return fluid_; }
  double max_density_deviation() const { return max_density_deviation_; }

 private:
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& m) {
    ar.io(m.fluid_.fluid.x, m.fluid_.fluid.v, m.fluid_.wall.x, m.fluid_.time, m.fluid_.steps,
          m.max_density_deviation_);
  }
  FluidCell fluid_;
  bool implicit_;
  double dt_;
  double stress_ = 0, max_density_deviation_ = 0;
  ShearCell no_particles_;
  DemPairLists no_lists_;
  PairSums no_pairs_;
};

// The fluid-only model of a scene, its step chosen from the SPH limits.
struct FluidOnlyChoice {
  bool implicit_viscosity;
  double dt;                           // s, landing on t_end
  long steps;
  std::vector<StabilityLimit> limits;  // of the scheme used, at start
};
FluidOnlyChoice choose_fluid_only_step(const SceneConfig& cfg, const FluidCell& cell, double t_end);

// Runs from rest for `t_end` seconds. Viscosity is implicit for integrator
// "implicit", and for "auto" when the viscous limit is the binding one;
// explicit otherwise. dt = cfg.dt (refused above a limit) or
// cfg.dt_safety x the binding limit, shortened to land on t_end.
// Throws InputError for a non-SPH model or volume_fraction != 0.
CouetteSphResult run_couette_sph(const SceneConfig& cfg, double t_end);

}  // namespace mrf
