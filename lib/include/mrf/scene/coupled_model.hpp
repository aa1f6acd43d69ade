// The two-way coupled DEM-SPH models `demsph_stokes` (model 2) and
// `demsph_dd` (model 3), REFERENCE.md §4, §6: the DEM particles of model 1
// (contact + dipole forces, same pair lists) in the SPH carrier of
// fluid/wcsph.hpp, whose walls sit at the DEM wall planes and move with them.
//
// Averaged equations, model A (Anderson-Jackson; Robinson, Ramaioli & Luding
// 2014): porosity eps_a = 1 - sum_i V_p W_ai at the SPH particles; the SPH
// summation density is the superficial density eps rho_f (fluid particle
// mass (1 - phi) rho_f dx^3, so the mean intrinsic density is rho_f); the
// EOS takes the intrinsic density rho/eps. The SPH pressure and viscous sums
// divided by the superficial density give the mixture's -grad p + div tau per
// unit fluid mass; each particle then feels the generalised buoyancy
// F_b = V_p (-grad p + div tau)_i (Shepard-interpolated), and its reaction
// goes back to the fluid with the drag reaction. Together the fluid is left
// with eps (-grad p) + ...: model A, not model B (pinned by the fixed-bed and
// sedimentation tests in verification/coupling/).
//
// Two time-stepping schemes (CoupledStepping):
//
// inertial, multi-rate: one explicit SPH step of dt_fluid holds
// `substeps` DEM sub-steps (the Hertz contact step) that integrate the drag
// exactly for particle + fluid parcel (integrate/coupled_steps.hpp) with the
// interpolated fluid velocity, porosity and friction coefficient frozen over
// the fluid step; the accumulated impulse (and buoyancy) is scattered back to
// the SPH particles with the same kernel weights (coupling/exchange.hpp), so
// momentum of particles + fluid + walls is conserved to round-off.
//
// inertialess (particle Stokes number small): v_i = u_i + F_i / gamma_i with
// u_i, eps_i and gamma_i(eps_i) interpolated as above, the Hertz contacts
// implicit and the dipole forces explicit (integrate/implicit_stepper.hpp,
// the scheme of model 1, error-controlled steps). The fluid at the particles
// yields within the step as the scatter and gather of the exchange make it
// (coupling/fluid_response.hpp), which makes the interphase drag relaxation
// implicit. An
// inertialess particle passes its whole non-hydrodynamic force (contacts,
// dipoles, body force) to the fluid through the drag; that force times the
// step is scattered back to the SPH particles, so momentum of fluid + walls
// is conserved to round-off (the particles carry none). The SPH fluid then
// advances over the step in explicit sub-steps no longer than dt_fluid.
#pragma once
#include <optional>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/coupling/fluid_response.hpp"
#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/implicit_fluid.hpp"
#include "mrf/integrate/coupled_steps.hpp"
#include "mrf/integrate/implicit_stepper.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/dem_model.hpp"
#include "mrf/scene/model.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

enum class CoupledDrag { stokes, di_felice };
enum class CoupledScheme { inertial, inertialess };
const char* to_string(CoupledScheme s);

struct CoupledStepping {
  CoupledScheme scheme = CoupledScheme::inertial;
  double dt_fluid = 0;    // s: inertial, the fluid step; inertialess, the longest SPH sub-step
  int substeps = 1;       // inertial: DEM sub-steps per fluid step
  double dt_max = 0;      // inertialess: longest step (stability bounds of the explicit parts, s)
  // inertialess: the SPH terms taken by backward Euler (viscosity: dt_fluid
  // then the CFL bound; pressure and viscosity: the advective bound)
  SphImplicit sph = SphImplicit::none;
  double sph_skin = 0;    // Verlet skin of the SPH pairs (m; 0 = search every step)
  double coupling_skin = 0;  // Verlet skin of the DEM-SPH coupling pairs (m; 0 = search every step)
  ImplicitOptions implicit;  // inertialess
};

// Sums over the DEM sub-steps of one fluid step (for the stress observables).
struct CoupledStepSums {
  PairSums dem;                          // wall_fz and virials averaged over sub-steps; max_overlap the max
  double fluid_stress = 0;               // SPH wall shear stress at the start of the step (Pa)
  // Virial shear stress -(1/V) sum r_x F_z of the fluid pairs (SPH pressure
  // + Morris viscous, fluid-wall pairs included) and of the particle-fluid
  // exchange (each particle's force split over its SPH neighbours with the
  // scatter weights), Pa: with the particle pair virial, the volume side of
  // the wall stress (REFERENCE §7).
  double fluid_virial = 0, exchange_virial = 0;
  double eps_min = 1, eps_max = 1;       // porosity range at the SPH particles
  std::size_t eps_clamped = 0;           // SPH particles at the porosity floor
  long wall_reflections = 0;             // SPH particles reflected at a wall plane since the start
};

class CoupledModel final : public Model {
 public:
  // `fluid` built for the same box (fluid mass already scaled, see
  // build_coupled_fluid). dt_fluid (s) is split into `substeps` DEM sub-steps.
  CoupledModel(ShearCell cell, const DemParams& params, FluidCell fluid, CoupledDrag law, double dt_fluid,
               int substeps);
  CoupledModel(ShearCell cell, const DemParams& params, FluidCell fluid, CoupledDrag law, const CoupledStepping& s);

  // One fluid step (inertial) or one accepted implicit step (inertialess).
  void step() override;
  CoupledScheme scheme() const { return stepping_.scheme; }
  // Inertialess: the step just taken (s), the implicit scheme's work, and
  // the stop time the step that would pass it is shortened to.
  double dt() const override { return implicit_ ? implicit_->dt() : dt_; }
  const ImplicitCounters& implicit_counters() const { return implicit_->counters(); }
  void set_stop_time(double t) override {
    if (implicit_) implicit_->set_stop_time(t);
  }
  bool adaptive() const override { return implicit_.has_value(); }
  StepSample sample() const override;
  void finish(RunSummary& s) const override;
  std::string progress() const override;
  long fluid_substeps() const { return fluid_substeps_; }  // inertialess: SPH sub-steps so far
  long sph_pair_builds() const { return sph_pairs_.builds; }
  long viscous_iterations() const { return viscous_iterations_; }  // implicit SPH: CG iterations so far

  const ShearCell& cell() const override { return cell_; }
  const FluidCell& fluid() const { return fluid_; }
  const DemParams& params() const { return p_; }
  const DemPairLists& lists() const override { return lists_; }
  const CoupledStepSums& sums() const { return sums_; }
  double dt_fluid() const { return dt_; }
  double dt_dem() const { return dt_ / substeps_; }
  int substeps() const { return substeps_; }
  double time() const override { return time_; }
  long steps() const override { return steps_; }
  long dem_steps() const { return steps_ * substeps_; }

  // Total momentum of particles (none when inertialess) + fluid (kg m/s) and the impulse the walls
  // and body forces have given them since the start (N s): momentum() -
  // momentum at start equals external_impulse() to round-off.
  Vec3 momentum() const;
  const Vec3& external_impulse() const { return external_impulse_; }

  // Friction coefficient and fluid velocity at the particles of the last step.
  const ParcelCoupling& coupling() const { return coupling_; }
  const std::vector<Vec3>& fluid_velocity_at_particles() const { return u_at_; }
  const std::vector<double>& porosity_at_particles() const { return eps_at_; }
  // Force per particle besides drag and the DEM forces (buoyancy), N.
  const std::vector<Vec3>& buoyancy() const { return buoyancy_; }
  // Constant extra force on every free particle (N), e.g. for settling tests.
  void set_body_force(const Vec3& f) { body_force_ = f; }

  // Checkpoint: the state carried from one fluid step to the next (DEM
  // particles, walls and pair lists, SPH particles, counters, clock), so
  // that a restored model continues bit for bit (scene/coupled_checkpoint.cpp;
  // what is not saved is listed there). load() expects a model built from
  // the same scene; until the next step() the accessors of the last step's
  // coupling fields (coupling(), buoyancy(), ...) and sums() other than
  // wall_reflections and the porosity range are not restored.
  void save(ArchiveWriter& out) const override { serialize(out, *this); }
  void load(ArchiveReader& in) override;

 private:
  // What is and is not saved: scene/coupled_checkpoint.cpp.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& m) {
    serialize_dem_state(ar, m.cell_, m.lists_);
    ar.io(m.fluid_.fluid.x, m.fluid_.fluid.v, m.fluid_.fluid.a_ext, m.fluid_.fluid.rest_density, m.fluid_.wall.x,
          m.fluid_.wall.v, m.sums_.wall_reflections, m.external_impulse_, m.time_, m.steps_, m.eps_seen_min_,
          m.eps_seen_max_, m.clamped_steps_, m.coupling_cache_.dem_ref, m.coupling_cache_.sph_ref,
          m.coupling_cache_.builds, m.mirrored_, m.coupling_cache_time_);
    if (m.implicit_) ar.io(*m.implicit_, m.fluid_substeps_, m.sph_pairs_, m.viscous_iterations_);
  }
  void update_coupling_pairs();
  void prepare_coupling(const std::vector<Vec3>& a_fluid);
  void update_dem_forces();
  void dem_substep();
  void check_dem() const;
  void inertialess_step();
  void tally();  // run-long porosity records of the step
  // SPH forces per unit mass (with or without viscosity); `sample` sets the
  // fluid stress sums of the step
  std::vector<Vec3> fluid_acceleration(bool viscous, bool sample);
  void advance_fluid(double dt, const std::vector<Vec3>& kick, std::vector<Vec3>& a, SphImplicit implicit);
  void exchange_with_fluid(const std::vector<Vec3>& impulse, std::vector<Vec3>& kick, double dt);

  ShearCell cell_;
  DemParams p_;
  FluidCell fluid_;
  CoupledDrag law_;
  double dt_;
  int substeps_;
  DemPairLists lists_;
  ForceBuffers buffers_;
  std::vector<CouplingPair> pairs_, solid_pairs_;  // real particles; with wall mirror images
  std::vector<Vec3> pair_grads_;  // inertialess: the kernel gradient of each of pairs_ (shepard_rate)
  std::vector<Vec3> solid_;
  CouplingPairCache coupling_cache_;
  std::vector<std::uint32_t> mirrored_;  // the particles whose wall mirrors the cache holds
  double coupling_cache_time_ = 0;       // of its build
  ShepardField shepard_;
  std::vector<Vec3> u_at_, buoyancy_, f_old_, f_new_;
  std::vector<double> eps_at_;
  ParcelCoupling coupling_;
  ParcelState parcel_;
  CoupledStepSums sums_;
  Vec3 external_impulse_ = Vec3::Zero();
  Vec3 body_force_ = Vec3::Zero();
  double overlap_limit_;
  double time_ = 0;
  long steps_ = 0;
  CoupledStepping stepping_;
  std::optional<ImplicitStepper> implicit_;  // inertialess
  ImplicitDrift drift_;
  FluidResponse response_;
  SphPairCache sph_pairs_;
  long viscous_iterations_ = 0;
  // Over the run (checkpointed): porosity range at the SPH particles and the
  // steps at which some SPH particle sat at the porosity floor.
  double eps_seen_min_ = 1, eps_seen_max_ = 0;
  long clamped_steps_ = 0;
  Vec3 momentum0_ = Vec3::Zero();  // at construction
  std::vector<Vec3> fc_end_;
  long fluid_substeps_ = 0;
};

// The SPH carrier of a coupled scene: build_fluid_cell on the scene box with
// the fluid particle mass scaled by (1 - phi) (phi of the DEM particles), so
// that the superficial density of the rest state is (1 - phi) rho_f.
FluidCell build_coupled_fluid(const SceneConfig& c, const ShearCell& cell);

// Time-step limit of the explicit SPH step in the averaged equations: the
// viscous bound 0.125 h^2 eps_min rho_f / eta (the superficial density
// eps rho_f carries the momentum) beside the CFL bound (s).
double coupled_viscous_limit(const FluidCell& f, double eps_min);

}  // namespace mrf
