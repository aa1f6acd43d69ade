// Building blocks of the DEM integrators (REFERENCE.md §3). Each acts on
// whole arrays and knows one piece of physics; the schemes compose them.
#pragma once
#include <vector>

#include "mrf/box.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/state.hpp"

namespace mrf {

// Target velocity of the drag relaxation, w = u(x) + f/gamma, with the
// imposed Couette profile u = (0, 0, gdot x_x).
inline Vec3 drift_velocity(const Vec3& x, const Vec3& f, double inv_gamma, double shear_rate) {
  return couette_velocity(x, shear_rate) + inv_gamma * f;
}

// Exponential velocity Verlet, first half: with w_n frozen over the step the
// drag equation dv/dt = (w_n - v)/tau is solved exactly (REFERENCE §3):
//   x += w dt + tau (v - w)(1 - a),   v = w + (v - w) a,   a = exp(-dt/tau).
// Stores w_n in `w` for the second half.
void exp_verlet_advance(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                        std::vector<Vec3>& w, double tau, double gamma, double shear_rate, double dt);

// Second half, after the forces at x_{n+1}: taking w linear in time over the
// step adds (w_{n+1} - w_n) (1 - tau (1 - a)/dt) to v. Exact for constant w,
// velocity Verlet when tau -> infinity, explicit Euler on x when tau -> 0.
void exp_verlet_correct(const std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                        const std::vector<Vec3>& w, double tau, double gamma, double shear_rate,
                        double dt);

// 1 - (1 - exp(-s))/s, accurate for small s (the weight of the velocity correction).
double exp_verlet_weight(double s);

// Inertialess step: v = u(x) + f/gamma, x += v dt (explicit Euler).
void overdamped_drift(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                      double gamma, double shear_rate, double dt);

// Move the wall spheres with their prescribed velocity (0, 0, gdot x_wall).
void move_walls(WallParticles& walls, double shear_rate, double dt);

// Wrap positions into the periodic box in y and z.
void wrap_all(std::vector<Vec3>& x, const Box& box);

}  // namespace mrf
