// Steepest descent along the gradient flow dx/dt = f (one mobility for every
// particle): the zero-rate limit of the overdamped Stokes-drag dynamics of
// model 1 with the drive switched off, so the minimum it reaches is the one
// that model's own relaxation would reach, not one an inertial (FIRE) or
// quasi-Newton (L-BFGS) minimiser jumps to (reports/quasistatic/minimiser.md).
// Explicit Euler steps x += h f with h = step (m/N) below the stability
// limit 2/lambda_max of the stiffest contact mode, each particle's move
// capped at max_step. Slow: its iterations grow with the condition number
// (FIRE's with its square root). Knows no physics: the caller supplies the
// forces, with the contract of FireForce. SI: m, N.
#pragma once
#include <string>
#include <vector>

#include "mrf/quasistatic/fire.hpp"
#include "mrf/vec.hpp"

namespace mrf {

struct DescentOptions {
  double force_tol = 0;      // converged when max_i |f_i| < force_tol (N)
  long max_evaluations = 0;  // force evaluations allowed, the first included
  double step = 0;           // h (m/N): the displacement per unit force of one iteration
  double max_step = 0;       // largest displacement of one particle in one iteration (m)

  // InputError naming the field (prefix + name) on a non-positive value.
  void validate(const std::string& key_prefix = "descent.") const;
};

struct DescentResult {
  bool converged = false;
  long evaluations = 0;   // the first (at the start point) included
  double max_force = 0;   // N, at the returned positions
  double energy = 0;      // J, the callback's there
  std::string stop_reason;  // "converged" or "max_evaluations"
};

// Minimises from x (modified in place); f holds the forces at the returned
// x. NumericalError on a non-finite force.
DescentResult descent_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const DescentOptions& o,
                               const FireForce& force);

}  // namespace mrf
