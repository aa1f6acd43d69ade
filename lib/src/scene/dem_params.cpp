#include "mrf/scene/dem_params.hpp"

#include "mrf/coupling/drag_laws.hpp"
#include "mrf/forces/dipole.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/forces/hertz.hpp"

namespace mrf {

namespace {
constexpr double k_zeta3 = 1.2020569031595942;
}

double expected_contact_load(const SceneConfig& c) {
  const double magnetic = 2.0 * k_zeta3 * dipole_contact_force(c.radius, c.magnetization);
  const double hydro = stokes_gamma(c.viscosity, c.radius) * c.shear_rate * c.gap * c.gap /
                       (16.0 * c.radius);
  return magnetic + hydro;
}

double expected_impact_speed(const SceneConfig& c) {
  const double pair = 2.0 * dipole_contact_force(c.radius, c.magnetization) / stokes_gamma(c.viscosity, c.radius);
  return 2.0 * k_zeta3 * pair + 2.0 * c.radius * c.shear_rate;
}

DemParams dem_params(const SceneConfig& c) {
  DemParams p{};
  p.radius = c.radius;
  p.mass = c.density * sphere_volume(c.radius);
  p.moment = dipole_moment(c.radius, c.magnetization);
  // model dem_dd: the Di Felice coefficient at zero slip (Re -> 0) and the cell's mean porosity
  p.gamma = c.model == ModelId::dem_dd
                ? di_felice_drag_coefficient(0.0, 1.0 - c.volume_fraction, 2.0 * c.radius, c.fluid_density, c.viscosity)
                : stokes_gamma(c.viscosity, c.radius);
  p.tau_p = relaxation_time(p.mass, p.gamma);
  p.hertz_k = hertz_stiffness(c.youngs_modulus, c.poisson_ratio, c.radius, c.radius);
  p.dipole_pref = dipole_prefactor(p.moment);
  p.dipole_cutoff = c.dipole_cutoff;
  p.skin = c.skin > 0 ? c.skin : 0.2 * c.radius;
  p.adaptive_skin = !(c.skin > 0);
  p.shear_rate = c.shear_rate;
  p.viscosity = c.viscosity;
  p.contact_force = dipole_contact_force(c.radius, c.magnetization);
  p.expected_load = expected_contact_load(c);
  p.impact_speed = expected_impact_speed(c);
  return p;
}

double stokes_number(const DemParams& p) { return p.tau_p * p.shear_rate; }

double particle_reynolds(const SceneConfig& c) {
  return c.fluid_density * c.shear_rate * c.radius * c.radius / c.viscosity;
}

}  // namespace mrf
