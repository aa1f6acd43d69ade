// DEM sub-steps of the two-way coupled models (REFERENCE.md §3, §6): the
// drag is integrated exactly over a sub-step for a particle and its fluid
// parcel, so no time step is bound by the drag relaxation time, and the
// impulse the fluid gives the particle is accumulated exactly.
//
// Why a parcel and not a frozen fluid velocity: with a frozen u_i the
// particle relaxes fully to u_i within a fluid step (dt_f >> tau_p), and the
// back-reaction then kicks the fluid by (m_p / m_fluid) times the slip. At
// the mass loading of an iron suspension, rho_p phi / (rho_f eps) ~ 3.3 > 1,
// that explicit exchange is unstable whatever dt_f. Letting the fluid
// velocity at the particle, u_i, respond to the exchanged impulse with the
// inertia M_i it really has (coupled_model.cpp derives M_i from the same
// kernel weights that scatter the reaction) makes the two-body relaxation
// exact and unconditionally stable, and momentum still goes to the SPH
// particles exactly: the fluid receives minus the accumulated impulse.
//
// Per particle i, over one sub-step with the non-drag force F on the
// particle and the parcel acceleration g (non-drag forces on the fluid per
// unit fluid mass) frozen:
//   m   dv/dt = gamma (u - v) + F
//   M   du/dt = -gamma (u - v) + M g
// Mixture velocity V = (m v + M u)/(m + M) accelerates uniformly with
// (F + M g)/(m + M); slip s = u - v relaxes exactly:
//   ds/dt = g - F/m - lambda s,  lambda = gamma (1/m + 1/M).
// With 1/M = 0 (fluid not set in motion) this is the exponential Verlet step
// of model 1 (integrate/steps.hpp) with w = u + F/gamma.
#pragma once
#include <vector>

#include "mrf/vec.hpp"

namespace mrf {

// Per-particle coupling data, frozen over one fluid step.
struct ParcelCoupling {
  std::vector<double> gamma;     // drag friction coefficient, F_d = gamma (u - v) (kg/s)
  std::vector<double> inv_mass;  // 1/M_i, inverse inertia of the fluid at the particle (1/kg); 0 = infinite
  std::vector<Vec3> g;           // parcel acceleration from the non-drag fluid forces (m/s^2)
};

// Per-particle state carried across the sub-steps of one fluid step.
struct ParcelState {
  std::vector<Vec3> u;        // fluid velocity at the particle (m/s)
  std::vector<Vec3> impulse;  // drag impulse fluid -> particle accumulated (N s)
};

// Advance x, v and the parcel velocity by dt with the non-drag forces f
// (N, frozen); adds the drag impulse m dv - f dt to state.impulse.
void parcel_advance(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                    const ParcelCoupling& c, ParcelState& state, double mass, double dt);

// Second half, after the forces f_new at the new positions: taking the force
// linear in time over the sub-step corrects v and u exactly for the linear
// part (for 1/M = 0 this is exp_verlet_correct of model 1); the impulse is
// corrected so that the particle's momentum change stays
// (f_old + f_new) dt / 2 + drag impulse.
void parcel_correct(std::vector<Vec3>& v, const std::vector<Vec3>& f_old, const std::vector<Vec3>& f_new,
                    const ParcelCoupling& c, ParcelState& state, double mass, double dt);

// 1 - (1 - exp(-s))/s, accurate for small s (same weight as model 1's
// exponential Verlet correction).
double parcel_weight(double s);

}  // namespace mrf
