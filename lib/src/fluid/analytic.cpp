#include "mrf/fluid/analytic.hpp"

#include <algorithm>
#include <cmath>

#include "mrf/vec.hpp"

namespace mrf {

namespace {

// Number of series terms after which exp(-n^2 pi^2 nu t/L^2) < 1e-17; at
// t = 0 the series converges only conditionally and is cut at 1e5 terms.
int series_terms(double t, double L, double nu) {
  const double s = k_pi * k_pi * nu * t / (L * L);
  if (s <= 0.0) return 100000;
  return std::clamp(static_cast<int>(std::ceil(std::sqrt(40.0 / s))) + 1, 1, 100000);
}

double couette_coefficient(int n, double v_lo, double v_hi) {
  const double sign = (n % 2 == 0) ? 1.0 : -1.0;
  return -2.0 * (v_lo - sign * v_hi) / (n * k_pi);
}

}  // namespace

double couette_startup_velocity(double xp, double t, double L, double nu, double v_lo, double v_hi) {
  double u = v_lo + (v_hi - v_lo) * xp / L;
  const int nmax = series_terms(t, L, nu);
  for (int n = 1; n <= nmax; ++n) {
    const double k = n * k_pi / L;
    u += couette_coefficient(n, v_lo, v_hi) * std::sin(k * xp) * std::exp(-k * k * nu * t);
  }
  return u;
}

double couette_startup_shear_rate(double xp, double t, double L, double nu, double v_lo, double v_hi) {
  double g = (v_hi - v_lo) / L;
  const int nmax = series_terms(t, L, nu);
  for (int n = 1; n <= nmax; ++n) {
    const double k = n * k_pi / L;
    g += couette_coefficient(n, v_lo, v_hi) * k * std::cos(k * xp) * std::exp(-k * k * nu * t);
  }
  return g;
}

double poiseuille_startup_velocity(double xp, double t, double L, double nu, double f) {
  double u = f * xp * (L - xp) / (2.0 * nu);
  const int nmax = series_terms(t, L, nu);
  for (int n = 1; n <= nmax; n += 2) {
    const double k = n * k_pi / L;
    u -= 4.0 * f * L * L / (nu * std::pow(n * k_pi, 3)) * std::sin(k * xp) * std::exp(-k * k * nu * t);
  }
  return u;
}

}  // namespace mrf
