#include "mrf/integrate/coupled_steps.hpp"

#include <cmath>

namespace mrf {

double parcel_weight(double s) {
  if (s < 1e-4) return s * (0.5 - s * (1.0 / 6.0 - s / 24.0));
  return 1.0 + std::expm1(-s) / s;
}

void parcel_advance(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                    const ParcelCoupling& c, ParcelState& state, double mass, double dt) {
  const double inv_m = 1.0 / mass;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double k = c.inv_mass[i], mk = mass * k;
    const double mu = mk / (1.0 + mk);  // m/(m + M): weight of v in the mixture velocity
    const double lambda = c.gamma[i] * (inv_m + k);
    const double e = -std::expm1(-lambda * dt);  // 1 - exp(-lambda dt)
    const Vec3 v0 = v[i], s0 = state.u[i] - v0;
    const Vec3 mix0 = v0 + (1.0 - mu) * s0;                    // (m v + M u)/(m + M)
    const Vec3 acc = (k * f[i] + c.g[i]) / (1.0 + mk);          // (F + M g)/(m + M)
    const Vec3 s_inf = (c.g[i] - inv_m * f[i]) / lambda;
    const Vec3 s1 = s0 + e * (s_inf - s0);
    // integral of s over the step, written without cancellation for lambda dt << 1
    const Vec3 s_int = (dt * parcel_weight(lambda * dt)) * s_inf + (e / lambda) * s0;
    const Vec3 mix1 = mix0 + dt * acc;
    x[i] += dt * mix0 + (0.5 * dt * dt) * acc - (1.0 - mu) * s_int;
    v[i] = mix1 - (1.0 - mu) * s1;
    state.u[i] = mix1 + mu * s1;
    state.impulse[i] += mass * (v[i] - v0) - dt * f[i];
  }
}

void parcel_correct(std::vector<Vec3>& v, const std::vector<Vec3>& f_old, const std::vector<Vec3>& f_new,
                    const ParcelCoupling& c, ParcelState& state, double mass, double dt) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double k = c.inv_mass[i], mk = mass * k;
    const double lambda = c.gamma[i] * (1.0 / mass + k);
    const Vec3 df = f_new[i] - f_old[i];
    const Vec3 d_mix = (0.5 * dt * k / (1.0 + mk)) * df;                            // from (F + M g)/(m + M)
    const Vec3 d_slip = (-parcel_weight(lambda * dt) / (c.gamma[i] * (1.0 + mk))) * df;  // -c dF/(m lambda)
    const Vec3 dv = d_mix - d_slip / (1.0 + mk);
    v[i] += dv;
    state.u[i] += d_mix + (mk / (1.0 + mk)) * d_slip;
    state.impulse[i] += mass * dv - (0.5 * dt) * df;
  }
}

}  // namespace mrf
