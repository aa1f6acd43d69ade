// Weakly compressible SPH for the carrier fluid (REFERENCE.md §5): summation
// density, linear EOS, Adami wall pressure, pressure + Morris viscous +
// body-force accelerations, explicit and implicit-viscosity steps, and the
// time-step limits.
//
// Density by summation, rho_a = (1/S1) sum_b m W_ab over fluid and wall
// particles (S1 = lattice_kernel_sum, so the rest lattice has rho0 exactly),
// rather than by the continuity equation: it conserves mass exactly and
// cannot drift (the density error is set by the particle arrangement alone,
// reported by density_stats), and the wall layers give every fluid particle
// full support, so there is no deficiency at the walls. For the coupling of
// §6 the same sum over fluid particles is the superficial density eps rho_f.
#pragma once
#include <string>
#include <vector>

#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/implicit_fluid.hpp"
#include "mrf/fluid/viscosity.hpp"
#include "mrf/integrate/limit.hpp"

namespace mrf {

// Pressure acceleration of a from b (REFERENCE §5, momentum, first term):
// -m (p_a/rho_a^2 + p_b/rho_b^2) grad_a W_ab (m/s^2). Antisymmetric in a, b.
inline Vec3 pressure_pair_acceleration(double mass, double p_a, double rho_a, double p_b, double rho_b,
                                       const Vec3& r_ab, double r, double h) {
  return -mass * (p_a / (rho_a * rho_a) + p_b / (rho_b * rho_b)) * kernel_dwdr_over_r(r, h) * r_ab;
}

// Adami, Hu & Adams (2012) wall pressure from the fluid around wall
// particle w: p_w = [sum_f p_f W_wf + (g - a_w) . sum_f rho_f r_wf W_wf] / sum_f W_wf
// with r_wf = x_w - x_f; here g = (0, 0, body_force) and a_w = 0 (walls move
// at constant speed). Sums are accumulated by the caller (Pa).
inline double adami_wall_pressure(double sum_pw, double g_dot_sum_rho_r_w, double sum_w) {
  return sum_w > 0.0 ? (sum_pw + g_dot_sum_rho_r_w) / sum_w : 0.0;
}

// Adds the pressure accelerations (fluid-fluid and fluid-wall) to a.
void add_pressure_acceleration(const FluidCell& c, std::vector<Vec3>& a);

// Body force plus the per-particle extra acceleration a_ext (m/s^2).
std::vector<Vec3> external_acceleration(const FluidCell& c);

// Explicit step (symplectic Euler: v += dt a(x, v); x += dt v). First order
// in time, which is enough: at the viscous limit dt ~ h^2/nu the time error
// is O(h^2) like the spatial one. Throws NumericalError on a non-finite
// state or a fluid particle beyond a wall plane, naming particle and step.
void step(FluidCell& c, double dt);

// Forces explicit, viscosity (or viscosity and the pressure increment) by
// backward Euler (implicit_fluid.hpp), then x += dt v_new. dt is free of the
// viscous limit (and of the acoustic one); accuracy is first order in dt.
// Same checks as step().
ImplicitSolveStats step_implicit(FluidCell& c, double dt, SphImplicit terms = SphImplicit::viscosity);

// Morris et al. (1997) limits (REFERENCE §5): CFL 0.25 h/(c0 + |v|max)
// (with implicit pressure the advective 0.25 h/|v|max), viscous 0.125 h^2/nu
// (left out when viscosity is implicit) and force 0.25 sqrt(h/|f|max) (left
// out when there is no force).
std::vector<StabilityLimit> stability_limits(const FluidCell& c, SphImplicit implicit);
// The viscous one alone (s): whether it binds decides implicit viscosity.
double viscous_limit(const FluidCell& c);

// Throws InputError (key numerics.dt) if dt exceeds a limit, naming it.
void check_time_step(const FluidCell& c, double dt, SphImplicit implicit);

}  // namespace mrf
