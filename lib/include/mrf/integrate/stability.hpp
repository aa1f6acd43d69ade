// Time-step limits of the DEM schemes (REFERENCE.md §2, §3). Each limit is
// {name, dt}; the automatic step is a safety fraction of the smallest one.
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "mrf/integrate/limit.hpp"
#include "mrf/params.hpp"

namespace mrf {

// Largest stable dt of the verlet_exp scheme (kick / exact drag-drift / kick)
// for a damped oscillator r'' = -omega^2 r - r'/tau: found from the spectral
// radius of the scheme's 2x2 amplification matrix, so it is exact for the
// scheme, from the inertial (dt ~ 2/omega) to the overdamped regime.
double verlet_exp_oscillator_limit(double omega, double tau);
// Spectral radius of that amplification matrix (exposed for tests).
double verlet_exp_amplification(double omega, double tau, double dt);

// Explicit-Euler overdamped limit for a pair of free spheres: dt < gamma/k_eff.
double overdamped_contact_limit(double gamma, double k_eff);

// Overlap (m) the contact limit is designed for: the static overlap under the
// expected load, and for the inertial scheme also the overlap of a head-on
// impact at the expected approach speed (REFERENCE TEST 2.1).
double expected_overlap(const DemParams& p, IntegratorId scheme);

// Contact candidates of an implicit step are the pairs within 2R + margin at
// the start of the step, margin = this x R; a step that moves a particle or
// the walls by more than margin/2 is rejected.
inline constexpr double k_contact_margin_over_radius = 0.4;

// All limits of a DEM scene for the given scheme. For `implicit` the contact
// and drag limits are infinite, and the binding one is the stability of its
// explicit dipole forces or the wall motion per step that the contact search
// allows: the largest step the error control may take.
// gap (m): wall-centre distance (the walls move at gdot gap / 2).
std::vector<StabilityLimit> dem_limits(const DemParams& p, double gap, IntegratorId scheme);

// Contact limit for the largest overlap actually seen (checked during a run).
double contact_limit_at_overlap(const DemParams& p, IntegratorId scheme, double overlap);


// Automatic choice of the integrator (numerics.integrator = "auto"): the
// explicit scheme whose binding limit is largest (ties to verlet_exp), unless
// that limit is more than k_implicit_preference times below the implicit
// step bound, then `implicit`. Measured on the small scene (one strain
// unit, one thread, side by side, BDF2): at Y = 0.2 GPa implicit took
// 0.11-0.12 s against verlet_exp's 0.21 s at Mn 1e-2 (limit ratio 6.3) and
// 0.06 s against 0.14 s at Mn 0.1 and 1 (ratio 4: both bound by the wall
// speed), so the costs meet near a ratio of 2. The factor stays at 5: where
// the walls bind both schemes (Mn >= 0.1 here, St >= 0.03) `auto` keeps the
// inertial scheme rather than drop the particle inertia for a 2x gain.
inline constexpr double k_implicit_preference = 5.0;
// Particles may be taken as inertialess (the implicit scheme, v = u + F/gamma)
// up to this Stokes number tau_p gdot; above it `auto` keeps their inertia.
// Measured by scripts/stokes-boundary (small scene, Mn = 1e-2, density
// varied, 3 seeds; reports/inertia/stokes_boundary.md), re-measured in
// session 17 on the current schemes (model 3 with the implicit SPH step):
// model 1's inertialess wall stress is +0.5 %, -3.4 % and -4.0 % of the
// inertial one at St = 3e-3, 5e-3 and 9e-3 (0.15, 1.5 and 1.7 combined
// standard errors) and departs by -8.9 % (3.4 errors) at 3e-2; model 3's
// agrees within 0.9 errors up to 3e-2 and departs at 9e-2 (+16 %, 17
// errors). Model 1's shift grows steadily from 5e-3 on, so the bound stays
// at 5e-3 rather than at the 9e-3 that a 2-error test alone would allow.
inline constexpr double k_inertialess_max_stokes = 5e-3;
IntegratorId auto_integrator(const std::vector<StabilityLimit>& verlet_exp,
                             const std::vector<StabilityLimit>& overdamped,
                             const std::vector<StabilityLimit>& implicit, double stokes_number);

// Largest overlap (m) whose Hertz stiffness the scheme still integrates
// stably at time step dt (bisection on the monotone contact limit).
double critical_overlap(const DemParams& p, IntegratorId scheme, double dt);

}  // namespace mrf
