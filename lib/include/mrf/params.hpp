// Parameters of the particle laws and schemes (SI), as the lower layers
// (forces/, integrate/, neighbors/) take them: derived once from a scene by
// scene/dem_params.hpp, or set by a test.
#pragma once

namespace mrf {

enum class IntegratorId { automatic, verlet_exp, overdamped, implicit };
const char* to_string(IntegratorId i);

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
  bool adaptive_skin = false;  // skin chosen for cost from the start value `skin` (neighbors/verlet_list.hpp)
};

}  // namespace mrf
