// Derived DEM parameters of a scene (SI): what the force laws and the
// integrators need, computed once from a validated SceneConfig.
#pragma once
#include "mrf/scene/config.hpp"

namespace mrf {

struct DemParams {
  double radius;         // m
  double mass;           // kg
  double moment;         // dipole moment m = M V_p along +x (A m^2)
  double gamma;          // Stokes friction 6 pi eta R (kg/s)
  double tau_p;          // drag relaxation time m/gamma (s)
  double hertz_k;        // Hertz prefactor, identical spheres (N/m^1.5)
  double dipole_pref;    // 3 mu0 m^2 / (4 pi) (N m^4)
  double dipole_cutoff;  // m
  double skin;           // Verlet skin (m)
  double shear_rate;     // 1/s
  double viscosity;      // Pa s
  double contact_force;  // head-to-tail dipole force at contact (pi/6) mu0 R^2 M^2 (N)
  double expected_load;  // largest contact load the time step is designed for (N)
  double impact_speed;   // largest expected approach speed of a contact pair (m/s)
};

DemParams dem_params(const SceneConfig& c);

// Largest contact load a run is expected to see (N): a chain's magnetic
// tension (2 zeta(3) times the contact force, REFERENCE §1) plus the drag
// of the shear flow on a gap-spanning chain, gamma gdot gap^2 / (16 R).
double expected_contact_load(const SceneConfig& c);

// Largest approach speed of two spheres meeting head-to-tail: the terminal
// relative speed 2 F/gamma under the contact force F, times 2 zeta(3) for
// chain ends pulled by whole chains (the random start makes such impacts),
// plus the relative shear speed 2R gdot.
double expected_impact_speed(const SceneConfig& c);

// Dimensionless numbers reported with every run (REFERENCE §3, §8).
double stokes_number(const DemParams& p);                    // tau_p gdot
double particle_reynolds(const SceneConfig& c);              // rho_f gdot R^2 / eta

}  // namespace mrf
