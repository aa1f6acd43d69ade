// Closed-form start-up flows between plates at x' = 0 and x' = L
// (REFERENCE.md §5, TESTS 5.2 and 5.3), used by the verification suite and
// by run_couette_sph to measure the profile error. Fluid at rest at t = 0.
// x' (m), t (s), L (m), nu (m^2/s), velocities (m/s), f (m/s^2).
#pragma once

namespace mrf {

// Plates moving along z at v_lo (x' = 0) and v_hi (x' = L) from t = 0:
//   u = v_lo + (v_hi - v_lo) x'/L + sum_n b_n sin(n pi x'/L) exp(-n^2 pi^2 nu t/L^2),
//   b_n = -2 (v_lo - (-1)^n v_hi)/(n pi).
// v_lo = 0, v_hi = V0 gives TEST 5.3. The shear cell has v_lo = -V, v_hi = +V:
// then only even n remain, b_n = 4V/(n pi). (REFERENCE's "V0 -> 2V0 in the
// lower wall's frame" would start the fluid at +V in that frame, not at rest.)
double couette_startup_velocity(double xp, double t, double L, double nu, double v_lo, double v_hi);

// du/dx' of the same flow (1/s); at x' = 0 or L times eta it is the wall stress.
double couette_startup_shear_rate(double xp, double t, double L, double nu, double v_lo, double v_hi);

// Body force f along z, plates at rest (TEST 5.2):
//   u = f x'(L - x')/(2 nu) - sum_{n>=0} 4 f L^2/(nu pi^3 (2n+1)^3) sin((2n+1) pi x'/L) exp(-(2n+1)^2 pi^2 nu t/L^2).
double poiseuille_startup_velocity(double xp, double t, double L, double nu, double f);

}  // namespace mrf
