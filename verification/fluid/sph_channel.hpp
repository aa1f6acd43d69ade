// Shared set-up of the SPH channel tests: oil-like carrier (eta = 0.1 Pa s,
// rho0 = 1000 kg/m^3, nu = 1e-4 m^2/s) between the shear-cell walls,
// L = 150 um, a thin periodic slab (3 x 3 particles per layer: the flows are
// one-dimensional, and periodic images keep full kernel support).
#pragma once
#include <cmath>
#include <functional>

#include "mrf/fluid/analytic.hpp"
#include "mrf/fluid/fluid_cell.hpp"
#include "mrf/fluid/fluid_observables.hpp"
#include "mrf/fluid/wcsph.hpp"

namespace mrf::test {

inline constexpr double k_gap = 150e-6;        // m
inline constexpr double k_eta = 0.1;           // Pa s
inline constexpr double k_rho = 1000.0;        // kg/m^3
inline constexpr double k_nu = k_eta / k_rho;  // m^2/s
inline constexpr double k_t_visc = k_gap * k_gap / k_nu;  // diffusion time L^2/nu (s)

// n_across particles across the gap; shear_rate (1/s), body_force (m/s^2);
// sound speed c0 (m/s, 0 = automatic) and lateral width in dx (>= 6 keeps
// every pair a single periodic image).
inline FluidCell channel(int n_across, double shear_rate, double body_force, double eta = k_eta, double c0 = 0.0,
                         int lateral = 3) {
  const double dx = k_gap / n_across;
  FluidParams p;
  p.viscosity = eta;
  p.density = k_rho;
  p.spacing = dx;
  p.shear_rate = shear_rate;
  p.body_force = body_force;
  p.sound_speed = c0;
  return build_fluid_cell(Box{k_gap, lateral * dx, lateral * dx}, p);
}

// Relative RMS difference of the fluid velocities of a against b.
inline double velocity_difference(const FluidCell& a, const FluidCell& b) {
  double d = 0, n = 0;
  for (std::size_t i = 0; i < a.fluid.size(); ++i) {
    d += (a.fluid.v[i] - b.fluid.v[i]).squaredNorm();
    n += b.fluid.v[i].squaredNorm();
  }
  return std::sqrt(d / n);
}

// Exact start-up Couette profile of the cell (walls at -V, +V), x in box coordinates.
inline std::function<double(double)> couette_exact(const FluidCell& c, double t) {
  const double v = 0.5 * c.params.shear_rate * c.box.gap, L = c.box.gap, nu = c.params.kinematic_viscosity();
  return [=](double x) { return couette_startup_velocity(x + 0.5 * L, t, L, nu, -v, v); };
}

inline std::function<double(double)> poiseuille_exact(const FluidCell& c, double t) {
  const double L = c.box.gap, nu = c.params.kinematic_viscosity(), f = c.params.body_force;
  return [=](double x) { return poiseuille_startup_velocity(x + 0.5 * L, t, L, nu, f); };
}

// Explicit dt: half the binding Morris limit.
inline double explicit_dt(const FluidCell& c) { return 0.5 * binding(stability_limits(c, SphImplicit::none)).dt; }

// Advances to time t with steps no longer than dt (the last one shortened
// so that t is reached exactly).
inline void run_to(FluidCell& c, double t, double dt, bool implicit) {
  while (c.time < t * (1 - 1e-12)) {
    const double h = std::min(dt, t - c.time);
    if (implicit)
      step_implicit(c, h);
    else
      step(c, h);
  }
}

}  // namespace mrf::test
