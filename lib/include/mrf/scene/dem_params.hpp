// Derived DEM parameters of a scene (SI): what the force laws and the
// integrators need, computed once from a validated SceneConfig.
#pragma once
#include "mrf/params.hpp"
#include "mrf/scene/config.hpp"

namespace mrf {

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
