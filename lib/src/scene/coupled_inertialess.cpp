// The inertialess step of the coupled models (scene/coupled_model.hpp):
// particles v = u + F/gamma in the SPH carrier, Hertz contacts implicit with
// the fluid's response inside the solve (integrate/implicit_stepper.hpp,
// coupling/fluid_response.hpp), then the SPH fluid in sub-steps.
#include <algorithm>
#include <cmath>

#include "mrf/fluid/wcsph.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/scene/coupled_model.hpp"

namespace mrf {

// Inertialess particles: force balance drag + buoyancy + F_c + F_nc + body = 0.
void CoupledModel::inertialess_step() {
  auto& f = cell_.free;
  const std::size_t n = f.size();
  const SphImplicit sph = stepping_.sph;
  // the coupling sees the whole fluid force, the explicit step with implicit
  // viscosity its non-viscous part
  std::vector<Vec3> a = fluid_acceleration(false, true);
  if (sph != SphImplicit::none) {
    std::vector<Vec3> whole = a;
    add_viscous_acceleration(fluid_, whole);
    prepare_coupling(whole);
  } else {
    add_viscous_acceleration(fluid_, a);
    prepare_coupling(a);
  }
  const std::vector<Vec3>& fc = implicit_->begin_step(lists_, f, cell_.walls, cell_.box);
  drift_.w0.resize(n);
  drift_.w1.resize(n);
  drift_.inv_gamma.resize(n);
  response_.set(n, pairs_, shepard_.s, fluid_.fluid.rho, fluid_.mass, FluidResponse::jacobian_bound(fluid_.h));
  drift_.coupling = &response_;
  std::vector<Vec3> f_nc(n);
  for (std::size_t i = 0; i < n; ++i) {
    f_nc[i] = f.f[i] - fc[i] + body_force_;  // non-contact, non-hydrodynamic force at x_n (N)
    drift_.inv_gamma[i] = 1.0 / coupling_.gamma[i];
    drift_.w0[i] = drift_.inv_gamma[i] * (f_nc[i] + buoyancy_[i]);  // relative to the carrier u_at_
    // The fluid at the particle feels its own forces (coupling_.g adds back
    // the reaction of the buoyancy, which the particle passes on with the
    // rest) and, through C, what every particle passes to it.
    drift_.w1[i] = coupling_.g[i] + coupling_.inv_mass[i] * buoyancy_[i];
  }
  response_.add(f_nc, 1.0, drift_.w1);
  // The carrier as the particle samples it changes also because the particle
  // and the SPH particles move (shepard_rate): the particle at u + v_rel,
  // v_rel its drift relative to the carrier at x_n, so that the carrier's
  // path is second order.
  std::vector<Vec3> v_p(n);
  for (std::size_t i = 0; i < n; ++i) v_p[i] = u_at_[i] + drift_.w0[i] + drift_.inv_gamma[i] * fc[i];
  const std::vector<Vec3> sampled = shepard_rate(pairs_, pair_grads_, fluid_.mass, fluid_.fluid.rho, fluid_.fluid.v, shepard_, v_p);
  for (std::size_t i = 0; i < n; ++i) drift_.w1[i] += sampled[i];
  drift_.u = u_at_;
  const double dt = implicit_->advance(drift_, f, cell_.walls, cell_.box, time_, steps_);
  advance_pair_lists(lists_, p_.shear_rate * dt);
  implicit_->contact_forces_end(f, cell_.walls, cell_.box, fc_end_);
  // What the fluid gave the particles (drag + buoyancy) is minus what they
  // pass on: -(F_c + F_nc + body) dt per particle.
  std::vector<Vec3> exchange(n), kick;
  Vec3 pushed = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    exchange[i] = -dt * (fc_end_[i] + f_nc[i]);
    pushed += fc_end_[i];
  }
  // Pair forces cancel: what is left of the particles' push is the walls'
  // contacts and the body force (the dipole pairs cancel in f_nc as well).
  external_impulse_ += dt * (pushed + static_cast<double>(n) * body_force_);
  exchange_with_fluid(exchange, kick, dt);
  // SPH sub-steps of at most dt_fluid, the kick spread evenly; the porosity
  // of the SPH particles is held over the step.
  const int k = std::max(1, static_cast<int>(std::ceil(dt / stepping_.dt_fluid - 1e-9)));
  const double h = dt / k;
  for (auto& q : kick) q /= k;
  const double t0 = time_;
  for (int s = 0; s < k; ++s) {
    if (s > 0) a = fluid_acceleration(sph == SphImplicit::none, false);
    advance_fluid(h, kick, a, sph);
    time_ = t0 + (s + 1) * h;
    sph_pairs_.strain += p_.shear_rate * h;
    refresh(fluid_, sph_pairs_);
  }
  time_ = t0 + dt;
  fluid_substeps_ += k;
  fluid_.time = time_;
  ++steps_;
  fluid_.steps = steps_;
  // the DEM forces first: they wrap the positions into the box, from which
  // the coupling pairs are then found (as after a checkpoint is loaded)
  sums_.dem = PairSums{};
  update_dem_forces();
  update_coupling_pairs();
  tally();
}

}  // namespace mrf
