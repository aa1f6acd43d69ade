// The one-way DEM-Stokes model (`dem_stokes`): free magnetic spheres, wall
// spheres (optional), imposed Couette flow, and one of three integrators:
//  verlet_exp  exponential velocity Verlet: drag exact over the step,
//              forces linear in time (integrate/steps.hpp)
//  overdamped  v = u(x) + F/gamma, x += v dt   (inertialess, first order)
//  implicit    inertialess, Hertz contacts implicit (BDF2, or backward Euler
//              at order 1), dipole and flow explicit; each step solved for the
//              contact forces (integrate/contact_dual.hpp); the step size is
//              chosen from a local error estimate, up to the dt given.
#pragma once
#include <limits>

#include "mrf/integrate/contact_dual.hpp"
#include "mrf/integrate/implicit_contact.hpp"
#include "mrf/integrate/stability.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

// Accuracy control of the implicit scheme. The local error of a step is
// estimated as half the distance between the corrector (backward Euler) and
// the predictor x_n + dt v_n (v_n the slope of the previous step), i.e.
// (dt/2)|v_{n+1} - v_n| ~ (dt^2/2)|x''|, the leading error term of IMEX Euler.
// The contact step is solved for the forces (dual, contact_dual.hpp; the
// default: 2.4x faster per strain unit than primal on the small scene at
// 200 GPa, no Newton failures) or for the positions (primal,
// implicit_contact.hpp; its linear solver is `solver`). Both solve the same
// backward Euler equations (verification/integrate/test_contact_dual.cpp).
enum class ContactFormulation { dual, primal };
const char* to_string(ContactFormulation f);

// Order 2 is IMEX BDF2 (SBDF2) with variable steps: backward differentiation
// of order 2 for the contacts, the explicit drift extrapolated linearly from
// the last two steps, and the local error estimated by Milne's device from a
// quadratic extrapolation of the last three positions,
// err = (2/11) |y - y_pred| (the constant of equal steps); the first two
// steps of a run are order 1.
struct ImplicitOptions {
  int order = 2;                         // 1: IMEX Euler; 2: IMEX BDF2
  double tol_over_radius = 1e-2;         // largest local error per step / R
  double newton_tol_over_radius = 1e-6;  // Newton converged: largest correction (primal) or overlap residual (dual) / R
  double linear_rtol = 1e-1;             // relative residual of each linear solve (inexact Newton)
  int max_newton = 20;                   // iterations before the step is retried at dt/4
  bool fixed_step = false;               // every step = the dt given (convergence tests); no error control
  ContactFormulation formulation = ContactFormulation::dual;
  ContactLinearSolver solver = ContactLinearSolver::pcg;  // primal only
};

// Work of the implicit scheme since construction.
struct ImplicitCounters {
  long rejected = 0;           // steps rejected by the error test or the displacement bound
  long newton_failures = 0;    // steps rejected because Newton did not converge
  long newton_iterations = 0;  // over all attempts
  long linear_iterations = 0;  // CG iterations (1 per Newton iteration for the direct solver)
  double dt_min = std::numeric_limits<double>::infinity(), dt_max = 0;  // accepted steps (s)
};

class DemModel {
 public:
  DemModel(ShearCell cell, const DemParams& params, IntegratorId scheme, double dt);

  // One (accepted) step. For the implicit scheme dt() is the step just taken
  // and the next one is chosen by the error control, at most max_dt().
  void step();
  void set_implicit_options(const ImplicitOptions& o) { opt_ = o; }
  // The implicit scheme shortens the step that would pass t (s) to end on it.
  void set_stop_time(double t) { stop_time_ = t; }
  const ImplicitCounters& implicit_counters() const { return counters_; }
  double max_dt() const { return dt_max_; }

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
  void implicit_step();
  struct Attempt {
    NewtonResult newton;
    double error = 0, displacement = 0;  // m
    std::uint32_t moved = 0;             // particle with the largest displacement
  };
  Attempt attempt(double dt, const NewtonOptions& nopt);
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
  // implicit scheme
  ImplicitOptions opt_;
  ImplicitCounters counters_;
  double dt_max_, dt_try_, stop_time_ = std::numeric_limits<double>::infinity();
  ContactNewton newton_;
  ContactDual dual_;
  std::vector<ContactPair> candidates_;
  // Free-free pairs within near_reach_ = 2R + margin + near skin at the
  // positions near_x_, taken from the (longer) dipole Verlet list; refreshed
  // when a particle has moved half the near skin. The contact candidates of
  // each step are searched here.
  std::vector<ContactPair> near_ff_;
  std::vector<Vec3> near_x_;
  double near_reach_ = 0;
  std::vector<Vec3> x0_, b_, fc_;
  WallParticles walls0_;
  // order 2: positions and explicit drift of the last accepted steps,
  // the step before dt_ (s), and how many accepted steps they hold (<= 2)
  std::vector<Vec3> x_prev_, x_prev2_, w_prev_;
  double dt_prev2_ = 0;
  int history_ = 0;
};

// The DEM part of a checkpoint, shared by DemModel and CoupledModel: free
// particles (x, v, f), wall positions and the Verlet lists as built (their
// reference positions decide the next rebuild, their order the round-off).
// load_dem_state throws NumericalError when the particle counts differ.
void save_dem_state(ArchiveWriter& out, const ShearCell& cell, const DemPairLists& lists);
void load_dem_state(ArchiveReader& in, ShearCell& cell, DemPairLists& lists);

}  // namespace mrf
