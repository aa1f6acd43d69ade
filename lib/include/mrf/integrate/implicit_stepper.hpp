// The inertialess implicit-contact scheme as an object that owns its history
// (REFERENCE.md §2-3), shared by every model whose particles are inertialess:
// the imposed Couette flow of model 1 and the SPH carrier of models 2 and 3.
//
// Per free particle i the drift over a step of length dt is
//   dx_i/dt = w0_i + (t - t_n) w1_i + F_c,i(x)/gamma_i + (t - t_n) sum_j C_ij F_c,j(x),
// w0 the explicit part at t_n (flow velocity at the particle plus the
// non-contact forces over gamma), w1 its rate of change within the step
// (zero in an imposed flow; for a coupled model the acceleration of the fluid
// at the particle), gamma_i the drag coefficient and C (optional,
// integrate/mobility.hpp) how the fluid velocity at i responds to the forces
// particles pass to it. The Hertz contacts F_c are implicit. Why the C term:
// an inertialess particle passes its whole non-drag force to the fluid
// through the drag, so the fluid at it accelerates within the step; taking
// that into the implicit solve makes the interphase drag relaxation (rate
// n gamma / (eps rho_f), ~3e7 1/s at phi = 0.3) unconditionally stable, as
// the parcel step of the inertial coupled scheme does (coupled_steps.hpp).
//
// IMEX Euler (order 1) or variable-step IMEX BDF2 (order 2):
//   y = b + c dt (F_c(y)/gamma + dt C F_c(y)),
//   order 1: b = x_n + dt (w0_n + dt w1_n), c = 1
//   order 2: omega = dt/dt_{n-1}, c = (1+omega)/(1+2 omega),
//            b = a1 x_n - a2 x_{n-1} + c dt ((1+omega) w0_n - omega w0_{n-1} + dt w1_n),
//            a1 = (1+omega)^2/(1+2 omega), a2 = omega^2/(1+2 omega),
// With a carrier velocity u (the SPH fluid at the particle), the drift is
// split into the carrier's path over the step,
//   D_n = dt u_n + (dt^2/2) (w1_n + C F_c)   (constant acceleration),
// and the motion y = x - X relative to it, which the formulas above advance
// with w0 the relative drift alone: order 2 becomes
//   x = a1 x_n - a2 (x_{n-1} + D_{n-1}) + D_n + c dt ((1+omega) w0_n - omega w0_{n-1} + F_c/gamma),
// order 1 x = x_n + D_n + dt (w0_n + F_c/gamma), and the error is estimated
// on y. Two reasons: extrapolating u as part of w0 counts the fluid's
// acceleration twice (once in the extrapolation, once in w1), a first-order
// error; and the explicit SPH carrier's step-to-step (acoustic) noise in u,
// which the fluid's own step bounds, would otherwise set the particles'
// error estimate and shorten their steps.
// solved for the contact forces (integrate/contact_dual.hpp, the default)
// or the positions (implicit_contact.hpp; uniform mobility only). The local
// error is estimated against a predictor (order 1: x_n + dt v_n; order 2:
// Milne's device on the quadratic through the last three positions,
// (2/11)|y - y_pred|) and sets the next step; a step is retried shorter when
// Newton fails (dt/4), a particle or the walls move more than half the
// contact margin (dt/2), or the error exceeds the tolerance.
#pragma once
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/integrate/contact_dual.hpp"
#include "mrf/integrate/implicit_contact.hpp"
#include "mrf/integrate/mobility.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/state.hpp"

namespace mrf {

enum class ContactFormulation { dual, primal };
const char* to_string(ContactFormulation f);

struct ImplicitOptions {
  int order = 2;                         // 1: IMEX Euler; 2: IMEX BDF2
  double tol_over_radius = 1e-2;         // largest local error per step / R
  double newton_tol_over_radius = 1e-6;  // Newton converged: largest correction (primal) or overlap residual (dual) / R
  double linear_rtol = 1e-1;             // relative residual of each linear solve (inexact Newton)
  int max_newton = 20;                   // iterations before the step is retried at dt/4
  bool fixed_step = false;               // every step = the dt given (convergence tests); no error control
  ContactFormulation formulation = ContactFormulation::dual;
  ContactLinearSolver solver = ContactLinearSolver::pcg;  // primal only
  ContactDual::Preconditioner dual_preconditioner = ContactDual::Preconditioner::automatic;  // dual only
};

// Work of the implicit scheme since construction.
struct ImplicitCounters {
  long rejected = 0;           // steps rejected by the error test or the displacement bound
  long newton_failures = 0;    // steps rejected because Newton did not converge
  long newton_iterations = 0;  // over all attempts
  long linear_iterations = 0;  // CG iterations (1 per Newton iteration for the direct solver)
  double dt_min = std::numeric_limits<double>::infinity(), dt_max = 0;  // accepted steps (s)
};

// The explicit part of one step and the mobility (see the header comment).
// w1 may be empty and coupling null (imposed flow: zero).
// With a carrier (u not empty), w0 holds the particle's drift relative to
// the carrier only, and the step is taken in the carrier's frame (below).
struct ImplicitDrift {
  std::vector<Vec3> w0;           // m/s
  std::vector<Vec3> w1;           // m/s^2
  std::vector<double> inv_gamma;  // 1/gamma_i (s/kg)
  MobilityCoupling* coupling = nullptr;
  std::vector<Vec3> u;            // carrier velocity at the particle at t_n (m/s); empty: none
};

// Contact geometry and law of the step: identical spheres of `radius` (m),
// Hertz prefactor (N/m^1.5) and the imposed shear rate (1/s).
struct ImplicitContactParams {
  double radius = 0, hertz_k = 0, shear_rate = 0;
};

class ImplicitStepper {
 public:
  // dt_max (s): the largest step (stability bounds of the explicit parts);
  // near_reach (m): reach of the near list of contact candidates, at most
  // the range of the free-free Verlet list it is taken from.
  ImplicitStepper(const ImplicitOptions& opt, const ImplicitContactParams& p, double dt_max, double near_reach);

  // Candidates of the coming step at the current positions (from the Verlet
  // lists valid there), and their Hertz forces per particle (N), which the
  // caller subtracts from its pair forces to form the explicit part.
  const std::vector<Vec3>& begin_step(const DemPairLists& lists, const FreeParticles& f, const WallParticles& walls,
                                      const Box& box);
  // One accepted step from the state of begin_step: f.x and f.v (the mean
  // velocity over the step) updated, walls moved; returns its length (s).
  // `time` (s) and `step` name the step in errors; dt_cap (s) lowers dt_max
  // for this step (a bound that changes during a run).
  double advance(const ImplicitDrift& d, FreeParticles& f, WallParticles& walls, const Box& box, double time,
                 long step, double dt_cap = std::numeric_limits<double>::infinity());
  // Contact forces of the accepted step on each free particle (N), as solved
  // (dual) or at the new positions (primal); pairwise opposite.
  void contact_forces_end(const FreeParticles& f, const WallParticles& walls, const Box& box,
                          std::vector<Vec3>& out) const;

  // The step that would pass t (s) is shortened to end on it.
  void set_stop_time(double t) { stop_time_ = t; }
  void set_options(const ImplicitOptions& o) { opt_ = o; }
  const ImplicitOptions& options() const { return opt_; }
  const ImplicitCounters& counters() const { return counters_; }
  double dt() const { return dt_; }          // the last accepted step (s)
  double max_dt() const { return dt_max_; }  // s
  // The contact candidates of the last step (pairs within 2R + margin at its
  // start); the list-completeness test checks them.
  const std::vector<ContactPair>& candidates() const { return candidates_; }

  // The history (last steps, next try, counters); the near list is derived:
  // a load drops it, so the next step rebuilds it from the loaded positions
  // (the models' archives call this through ArchiveWriter/Reader::io).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.dt_, s.dt_try_, s.newton_cap_, s.counters_, s.x_prev_, s.x_prev2_, s.w_prev_, s.carrier_prev_,
          s.carrier_prev2_, s.dt_prev2_, s.history_);
    if constexpr (!std::is_const_v<Self>) {
      s.near_x_.clear();
      s.near_strain_ = 0;
    }
  }

 private:
  struct Attempt {
    NewtonResult newton;
    double error = 0, displacement = 0;  // m; displacement: the largest non-affine one
    std::uint32_t moved = 0;             // particle with the largest non-affine displacement
  };
  Attempt attempt(double dt, const ImplicitDrift& d, const NewtonOptions& nopt, FreeParticles& f,
                  WallParticles& walls, const Box& box);

  ImplicitOptions opt_;
  ImplicitContactParams p_;
  ImplicitCounters counters_;
  double dt_, dt_max_, dt_try_, stop_time_ = std::numeric_limits<double>::infinity();
  double newton_cap_ = std::numeric_limits<double>::infinity();  // step bound after a Newton failure (s)
  ContactNewton newton_;
  ContactDual dual_;
  std::vector<ContactPair> candidates_;
  // Free-free pairs within near_reach_ = 2R + margin + near skin at the
  // positions near_x_, taken from the (longer) dipole Verlet list; refreshed
  // when a pair may have closed by the near skin (the bound of
  // neighbors/verlet_list.hpp with the strain near_strain_ since then).
  std::vector<ContactPair> near_ff_;
  std::vector<Vec3> near_x_;
  double near_reach_, near_strain_ = 0;
  std::vector<Vec3> x0_, b_, fc_, carrier_, fc_scratch_;  // carrier_: D_n of the attempt
  std::vector<double> mob_;
  WallParticles walls0_;
  // positions, explicit drift w0 (order 2) and carrier paths D of the last
  // accepted steps, the step before dt_ (s), and how many accepted steps
  // they hold (<= 2)
  std::vector<Vec3> x_prev_, x_prev2_, w_prev_, carrier_prev_, carrier_prev2_;
  double dt_prev2_ = 0;
  int history_ = 0;
};

}  // namespace mrf
