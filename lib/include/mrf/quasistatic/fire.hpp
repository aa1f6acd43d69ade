// FIRE 2.0 energy minimiser (Bitzek, Koskinen, Gähler, Moseler & Gumbsch,
// PRL 97, 170201 (2006); the 2.0 variant of Guénolé, Nöhring, Vaid, Houllé,
// Xie, Prakash & Bitzek, Comput. Mater. Sci. 175, 109584 (2020), their
// Algorithm 2): damped dynamics with semi-implicit Euler steps, the velocity
// mixed toward the force, the step raised after n_delay downhill steps and,
// on an uphill step (P = F.v <= 0), halved, the velocity zeroed and the
// positions taken half a step back. Knows no physics: the caller supplies
// the forces. SI: positions m, forces N, mass kg, time s.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "mrf/vec.hpp"

namespace mrf {

struct FireOptions {
  double force_tol = 0;      // converged when max_i |f_i| < force_tol (N)
  long max_iterations = 0;   // force evaluations allowed after the first
  double dt_start = 0;       // s
  double dt_max = 0;         // s
  double dt_min = 0;         // s, the step is not cut below it
  double max_step = 0;       // largest displacement of one particle in one iteration (m)
  double mass = 0;           // the same for every particle (kg); only the ratio dt^2/mass matters
  int n_delay = 20;          // downhill steps before dt grows; also the initial delay
  double f_inc = 1.1, f_dec = 0.5, alpha_start = 0.25, f_alpha = 0.99;
  long max_uphill = 2000;    // consecutive uphill steps before giving up

  // InputError naming the field (prefix + name) on a non-positive or
  // inconsistent value.
  void validate(const std::string& key_prefix = "fire.") const;
};

struct FireResult {
  bool converged = false;
  long iterations = 0;         // MD steps taken (one force evaluation each)
  double max_force = 0;        // max_i |f_i| at the returned positions (N)
  double energy = 0;           // the force callback's energy there (J)
  std::string stop_reason;     // "converged", "max_iterations" or "uphill"
};

// Must set f to the forces at the current x (both the caller's arrays given
// to fire_minimize) and return the energy (J). May wrap x in periodic
// directions. A component held fixed is one whose force it sets to zero.
using FireForce = std::function<double()>;

// Minimises from x (modified in place); f holds the forces at the returned
// x. The initial forces are evaluated first: a configuration already below
// the tolerance returns after 0 iterations. NumericalError on a non-finite
// force.
FireResult fire_minimize(std::vector<Vec3>& x, std::vector<Vec3>& f, const FireOptions& o, const FireForce& force);

// Largest |f_i| (N).
double max_force_norm(const std::vector<Vec3>& f);

}  // namespace mrf
