// Morris, Fox & Zhu (1997) laminar viscosity and no-slip walls
// (REFERENCE.md §5, momentum equation, second term; walls, Morris 1997),
// explicit; backward Euler in implicit_fluid.hpp.
#pragma once
#include <algorithm>
#include <vector>

#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/kernel.hpp"

namespace mrf {

// Regularisation of 1/r^2 in the Morris term, in units of h^2 (REFERENCE §5).
inline constexpr double k_morris_eps = 0.01;

// Pair weight K_ab (1/s) of the Morris term: a_a += K_ab (v_a - v_b) with
//   K_ab = m (mu_a + mu_b) (r_ab . grad_a W_ab) / (rho_a rho_b (r^2 + eps h^2)).
// K_ab <= 0 (dissipative) and, for equal masses, K_ab = K_ba: the operator
// conserves momentum and is symmetric negative semi-definite.
inline double morris_weight(double r, double h, double mass, double eta, double rho_a, double rho_b) {
  return mass * 2.0 * eta * r * r * kernel_dwdr_over_r(r, h) /
         (rho_a * rho_b * (r * r + k_morris_eps * h * h));
}

// Lattice consistency factor of the Morris operator, 1/S2 (1). With h/dx
// fixed the SPH sum is a quadrature whose error does not vanish under
// refinement. On the simple cubic lattice (particle volume dx^3) the Morris
// operator gives nu S2 u'' for u = u(x) and carries shear stress eta S2 u',
// S2 = -dx^3 sum_b (dW/dr / r) x_ab^2 r^2/(r^2 + eps h^2) (continuum value 1):
// S2 = 0.969 at h/dx = 1.3 (0.979 without eps), 0.99 at 1.5. Scaling the
// pair weight by 1/S2 makes both exact on the lattice (quadratic profiles,
// Couette wall stress = eta gdot), so what remains is the error of the
// walls, the time stepping and particle disorder.
double morris_lattice_correction(double dx, double h);

// Viscosity used in the Morris term: eta x morris_lattice_correction (Pa s).
inline double effective_viscosity(const FluidCell& c) { return c.params.viscosity * c.viscous_scale; }

// Morris (1997) wall extrapolation: wall particle B at depth d_B behind the
// plane, seen from fluid particle A at distance d_A in front of it, takes the
// velocity v_w - (d_B/d_A)(v_A - v_w), so v_A - v_B = beta (v_A - v_w) with
// beta = 1 + d_B/d_A. This is exact for a linear profile (steady Couette).
// Instead of Morris' cap beta <= 1.5, which breaks that exactness for the
// first fluid layer (d_A = dx/2), d_A is bounded below by d_min = dx/2, so
// beta stays finite for particles pushed closer to the wall.
inline double morris_wall_factor(double d_b, double d_a, double d_min) {
  return 1.0 + d_b / std::max(d_a, d_min);
}

// Distance of fluid position x from the plane of wall `side` (m).
inline double wall_distance(const FluidCell& c, const Vec3& x, int side) {
  return 0.5 * c.box.gap - side * x.x();
}

// Adds the Morris viscous acceleration of every fluid particle to a (m/s^2).
void add_viscous_acceleration(const FluidCell& c, std::vector<Vec3>& a);

// Viscous acceleration of fluid particle `pr.a` from wall particle `pr.b`:
// wall_viscous_weight x (v_a - v_w), the weight K_aB beta_aB (1/s, <= 0).
Vec3 wall_viscous_acceleration(const FluidCell& c, const SphPair& pr);
double wall_viscous_weight(const FluidCell& c, const SphPair& pr);

}  // namespace mrf
