// Parameters of the weakly compressible SPH carrier fluid (REFERENCE.md §5),
// SI units, validated against the shear-cell box, and the small pure laws
// derived from them: equation of state and automatic sound speed.
#pragma once
#include "mrf/box.hpp"

namespace mrf {

struct FluidParams {
  double viscosity = 0;            // eta, dynamic viscosity (Pa s)
  double density = 0;              // rho0, reference density (kg/m^3)
  double spacing = 0;              // dx, initial particle spacing (m)
  double h_over_dx = 1.3;          // smoothing length / spacing (1); Wendland: 1.3-2
  double sound_speed = 0;          // c0 (m/s); 0 = automatic (auto_sound_speed)
  double shear_rate = 0;           // gdot (1/s); walls move with v_z = gdot x_wall
  double body_force = 0;           // f, acceleration along z (m/s^2)
  double density_tolerance = 0.01; // delta, target relative density variation (1)
  double cg_tolerance = 1e-10;     // relative residual of the implicit viscous solve (1)
  // With a porosity field (coupled models): the EOS reference of every
  // particle is rho0 (true), or its intrinsic density at the start (false).
  bool common_eos_reference = true;

  // Throws InputError naming the scene key (fluid.viscosity, fluid.density,
  // fluid.sph_spacing, fluid.sound_speed, drive.shear_rate, box.*); the
  // parameters no scene sets (h_over_dx, body_force, density_tolerance,
  // cg_tolerance) are named "FluidParams::<name>" and said to be internal. Requires
  // gap, ly and lz to be whole multiples of the spacing (the lattice and the
  // wall layers must tile the periodic box) and ly, lz larger than the kernel
  // support 2h (so no particle sees its own periodic image).
  void validate(const Box& box) const;

  double h() const { return h_over_dx * spacing; }
  double kinematic_viscosity() const { return viscosity / density; }
};

// Morris, Fox & Zhu (1997) choice of c0 for a relative density variation
// delta (REFERENCE §5): c0^2 = max(V0^2, nu V0 / L0, |f| L0) / delta, with
// velocity scale V0 (m/s), length scale L0 (m), nu (m^2/s), f (m/s^2).
double morris_sound_speed(double v0, double l0, double nu, double body_force, double delta);

// c0 for the shear cell: params.sound_speed if given, else Morris with
// L0 = gap/2 and V0 = the larger of the wall speed gdot gap/2 and the
// Poiseuille peak f gap^2/(8 nu). Throws InputError if there is no flow
// scale to choose from.
double sound_speed(const FluidParams& p, const Box& box);

// Linear equation of state p = c0^2 (rho - rho0) (Pa) and its inverse.
// Linear rather than Tait: at |rho/rho0 - 1| < 1 % the two differ by
// < 3 % of p, the inverse (needed for the wall density) is exact, and with
// zero background pressure the pressure term vanishes on any uniform state.
inline double eos_pressure(double rho, double rho0, double c0) { return c0 * c0 * (rho - rho0); }
inline double eos_density(double p, double rho0, double c0) { return rho0 + p / (c0 * c0); }

}  // namespace mrf
