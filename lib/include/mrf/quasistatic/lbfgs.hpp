// Limited-memory BFGS energy minimiser (Nocedal & Wright, Numerical
// Optimization, 2nd ed. 2006: Algorithm 7.4, the two-loop recursion, and
// Algorithms 3.5/3.6, the line search for the Wolfe conditions), written here
// for the quasi-static driver (quasistatic/aqs.hpp) as the alternative to
// FIRE (quasistatic/fire.hpp). Knows no physics: the caller supplies the
// forces f = -grad E and the energy, with the contract of FireForce.
//
// Why the line search tests the directional derivative: near a minimum of a
// cell of thousands of spheres the energy change of a step (~ N f^2 / k)
// falls far below the round-off of the total energy (a sum of ~1e5-1e6 pair
// energies, relative round-off ~1e-13), so an Armijo test on the energy alone
// rejects every step once max |f| is below ~1e-3 F0 and the minimiser stalls.
// The forces stay accurate there. A trial step is therefore accepted on the
// strong-Wolfe curvature test |phi'(a)| <= c2 |phi'(0)| (phi(a) = E(x + a d),
// phi' = -f.d) together with an energy test that allows a round-off slack
// of energy_slack |E(x)| (the "approximate Wolfe" idea of Hager & Zhang,
// SIAM J. Optim. 16, 170 (2005)); the bracket is shrunk by a safeguarded
// secant on phi', which needs no energies. SI: positions m, forces N, J.
#pragma once
#include <string>
#include <vector>

#include "mrf/quasistatic/fire.hpp"
#include "mrf/vec.hpp"

namespace mrf {

struct LbfgsOptions {
  double force_tol = 0;          // converged when max_i |f_i| < force_tol (N), as FIRE
  long max_evaluations = 0;      // force evaluations allowed, the first included
  int memory = 10;               // correction pairs (s, y) kept
  double max_step = 0;           // largest displacement of one particle in one iteration (m)
  double initial_scale = 0;      // m/N: the first step (and the one after a reset, until a pair is stored) is
                                 // -initial_scale grad E, a guess of the inverse stiffness
  double c1 = 1e-4;              // sufficient decrease (Armijo)
  double c2 = 0.9;               // strong-Wolfe curvature: |phi'(a)| <= c2 |phi'(0)|
  double energy_slack = 1e-10;   // energy increase accepted as round-off, relative to |E(x)|
  int max_line_evaluations = 20; // trial steps of one line search before it counts as failed
  int max_failures = 5;          // consecutive failed line searches (each resets the memory) before giving up

  // InputError naming the field (prefix + name) on a non-positive or
  // inconsistent value.
  void validate(const std::string& key_prefix = "lbfgs.") const;
};

struct LbfgsResult {
  bool converged = false;
  long evaluations = 0;       // force evaluations, the first (at the start point) included
  long iterations = 0;        // accepted steps
  long resets = 0;            // memory resets (failed line searches, non-descent directions)
  double max_force = 0;       // max_i |f_i| at the returned positions (N)
  double energy = 0;          // the force callback's energy there (J)
  std::string stop_reason;    // "converged", "max_evaluations" or "line_search"
};

// Minimises from x (modified in place); f holds the forces at the returned
// x, and the callback's last evaluation was at the returned x (a caller may
// read its other sums). The forces are evaluated first: a configuration
// already below the tolerance returns after 1 evaluation. Convergence is
// tested at every evaluation, line-search trials included. NumericalError on
// a non-finite force.
LbfgsResult lbfgs_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const LbfgsOptions& o, const FireForce& force);

}  // namespace mrf
