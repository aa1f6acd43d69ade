// Particle-fluid drag laws of the coupled models, REFERENCE.md §3 and §4.
//
//   model 2 (demsph_stokes): F = 6 pi eta R (u - v)
//   model 3 (demsph_dd):     Dallavalle C_D with the Di Felice porosity
//                            function, canonical CFD-DEM variant (CFDEMcoupling
//                            DiFeliceDrag, PhasicFlow DiFeliceGrain).
//
// u is the interstitial (locally averaged) fluid velocity interpolated at the
// particle, v the particle velocity, eps the local porosity in (0, 1]. All SI.
//
// Both laws are "model A" forces: the particle ALSO feels the pressure-gradient
// (buoyancy) force -V_p grad p of the averaged formulation, which is applied
// separately and is not part of these functions. (CFDEM's "model B" would use
// F_d/eps as the whole interaction force instead; not what is implemented.)
//
// Every law is also given as a linearised friction coefficient beta with
// F = beta (u - v) exactly (beta may depend on |u - v| and eps), for the
// exponential drag integrator (§3): beta plays the role of gamma there.
#pragma once
#include <cmath>

#include "mrf/forces/drag.hpp"
#include "mrf/vec.hpp"

namespace mrf {

// ---------------------------------------------------------------- Di Felice

// Particle Reynolds number Re_p = eps d |u - v| rho_f / eta (dimensionless).
// Canonical CFDEM form: the slip velocity entering Re_p is the SUPERFICIAL
// slip eps |u - v|, so eps appears in Re_p (REFERENCE §4). The C_D and chi
// fits of Di Felice (1994) are written in terms of the superficial velocity;
// omitting eps here changes the low-Re ratio to Stokes at eps = 0.7 from
// 2.515 to 1.760 (§4), so the variant matters.
inline double particle_reynolds(double porosity, double diameter, double slip_speed, double fluid_density,
                                double viscosity) {
  return porosity * diameter * std::abs(slip_speed) * fluid_density / viscosity;
}

// Dallavalle (1948) drag coefficient C_D = (0.63 + 4.8/sqrt(Re))^2. Diverges
// as 23.04/Re for Re -> 0 (use di_felice_drag_coefficient for the force).
inline double dallavalle_cd(double re) {
  const double t = 0.63 + 4.8 / std::sqrt(re);
  return t * t;
}

// Di Felice (1994) porosity exponent chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2/2).
// chi -> 3.7 for Re -> 0 and Re -> inf, minimum 3.05 at Re = 10^1.5. Re <= 0
// (no slip, or rho_f = 0) returns the limit 3.7 exactly instead of going
// through log10(0) = -inf; the function is continuous there (the Gaussian has
// already underflowed to 0 at Re ~ 1e-300).
inline double di_felice_chi(double re) {
  if (!(re > 0.0)) return 3.7;
  const double l = 1.5 - std::log10(re);
  return 3.7 - 0.65 * std::exp(-0.5 * l * l);
}

// Friction coefficient beta (kg/s) of the Di Felice force, F = beta (u - v):
//   beta = (1/8) C_D rho_f pi d^2 eps^(2-chi) |u - v|.
// With a = sqrt(eta/(eps d rho_f)), 1/sqrt(Re) = a/sqrt(s) (s = |u - v|), so
//   C_D s = (0.63 sqrt(s) + 4.8 a)^2
//   beta  = (pi/8) eps^(2-chi) (0.63 d sqrt(rho_f s) + 4.8 sqrt(eta d/eps))^2,
// which has no 0*inf at s -> 0 (nor at rho_f = 0). Its s -> 0 limit is
//   beta_0 = 2.88 pi eta d eps^(1-chi) = 0.96 eps^-2.7 * 3 pi eta d,
// i.e. 0.96 eps^-2.7 times Stokes (REFERENCE §4, low-Re limit).
inline double di_felice_drag_coefficient(double slip_speed, double porosity, double diameter, double fluid_density,
                                         double viscosity) {
  const double s = std::abs(slip_speed);
  const double re = particle_reynolds(porosity, diameter, s, fluid_density, viscosity);
  const double chi = di_felice_chi(re);
  const double t = 0.63 * diameter * std::sqrt(fluid_density * s) + 4.8 * std::sqrt(viscosity * diameter / porosity);
  return 0.125 * k_pi * std::pow(porosity, 2.0 - chi) * t * t;
}

// Di Felice drag force on the particle (N), model A:
//   F = (1/8) C_D rho_f pi d^2 eps^2 |u - v| (u - v) eps^-chi.
// Exactly zero (no NaN) at u = v.
inline Vec3 di_felice_drag(const Vec3& u_minus_v, double porosity, double diameter, double fluid_density,
                           double viscosity) {
  return di_felice_drag_coefficient(u_minus_v.norm(), porosity, diameter, fluid_density, viscosity) * u_minus_v;
}

// ------------------------------------------------------------------- Stokes

// Model 2 friction coefficient gamma = 6 pi eta R (kg/s), independent of slip
// and porosity (single sphere in unbounded fluid, §3).
inline double stokes_coupled_drag_coefficient(double radius, double viscosity) {
  return stokes_gamma(viscosity, radius);
}

// Model 2 drag force F = 6 pi eta R (u - v) (N).
inline Vec3 stokes_coupled_drag(const Vec3& u_minus_v, double radius, double viscosity) {
  return stokes_coupled_drag_coefficient(radius, viscosity) * u_minus_v;
}

// ----------------------------------------------------- parameter structs
// Uniform interface for a coupled integrator templated on the law:
//   drag_force(law, u - v, eps), drag_coefficient(law, |u - v|, eps).

struct DiFeliceDrag {
  double diameter = 0.0;       // particle diameter d (m)
  double fluid_density = 0.0;  // rho_f (kg/m^3)
  double viscosity = 0.0;      // eta (Pa s)
};

struct StokesCoupledDrag {
  double radius = 0.0;     // particle radius R (m)
  double viscosity = 0.0;  // eta (Pa s)
};

inline double drag_coefficient(const DiFeliceDrag& law, double slip_speed, double porosity) {
  return di_felice_drag_coefficient(slip_speed, porosity, law.diameter, law.fluid_density, law.viscosity);
}
inline Vec3 drag_force(const DiFeliceDrag& law, const Vec3& u_minus_v, double porosity) {
  return di_felice_drag(u_minus_v, porosity, law.diameter, law.fluid_density, law.viscosity);
}

// Slip speed and porosity are ignored by the Stokes law (model 2).
inline double drag_coefficient(const StokesCoupledDrag& law, double /*slip_speed*/, double /*porosity*/) {
  return stokes_coupled_drag_coefficient(law.radius, law.viscosity);
}
inline Vec3 drag_force(const StokesCoupledDrag& law, const Vec3& u_minus_v, double /*porosity*/) {
  return stokes_coupled_drag(u_minus_v, law.radius, law.viscosity);
}

}  // namespace mrf
