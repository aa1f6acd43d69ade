#include "mrf/integrate/steps.hpp"

#include <cmath>

namespace mrf {

void exp_verlet_advance(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                        std::vector<Vec3>& w, double tau, double gamma, double shear_rate, double dt) {
  // Written as x += tau(1-a) v + dt c w and v = a v + (1-a) w, c = 1 - tau(1-a)/dt,
  // which has no cancellation when tau >> dt (w = f tau/m is then huge).
  const double s = dt / tau;
  const double a = std::exp(-s);
  const double one_minus_a = -std::expm1(-s);
  const double dt_c = dt * exp_verlet_weight(s);
  const double inv_gamma = 1.0 / gamma;
  w.resize(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    w[i] = drift_velocity(x[i], f[i], inv_gamma, shear_rate);
    x[i] += (tau * one_minus_a) * v[i] + dt_c * w[i];
    v[i] = a * v[i] + one_minus_a * w[i];
  }
}

double exp_verlet_weight(double s) {
  if (s < 1e-4) return s * (0.5 - s * (1.0 / 6.0 - s / 24.0));
  return 1.0 + std::expm1(-s) / s;
}

void exp_verlet_correct(const std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                        const std::vector<Vec3>& w, double tau, double gamma, double shear_rate,
                        double dt) {
  const double c = exp_verlet_weight(dt / tau);
  const double inv_gamma = 1.0 / gamma;
  for (std::size_t i = 0; i < x.size(); ++i)
    v[i] += c * (drift_velocity(x[i], f[i], inv_gamma, shear_rate) - w[i]);
}

void overdamped_drift(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<Vec3>& f,
                      double gamma, double shear_rate, double dt) {
  const double inv_gamma = 1.0 / gamma;
  for (std::size_t i = 0; i < x.size(); ++i) {
    v[i] = drift_velocity(x[i], f[i], inv_gamma, shear_rate);
    x[i] += dt * v[i];
  }
}

void move_walls(WallParticles& walls, double shear_rate, double dt) {
  for (auto& p : walls.x) p.z() += couette_velocity(p, shear_rate).z() * dt;  // each sphere on its wall plane
}

void wrap_all(std::vector<Vec3>& x, const Box& box) {
  for (auto& p : x) box.wrap(p);
}

}  // namespace mrf
