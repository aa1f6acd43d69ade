// Backward Euler on the stiff terms of the SPH momentum equation
// (REFERENCE.md §5): the Morris viscosity alone, or the viscosity and the
// pressure together, the pressure linearised about the current state.
//
// Pressure. With summation density and x_new = x + dt v_new, the density of
// particle a at the end of the step is, to first order in dt,
//   rho_a + dt (D v_new + d0)_a,  (D v)_a = sum_b g_ab . (v_a - v_b) + sum_w g_aw . v_a,
// g_ab = S1^-1 m grad_a W_ab over fluid (b) and wall (w) neighbours and
// d0_a = -sum_w g_aw . v_w (the walls move at their own speed). The linear
// EOS p = c0^2 (rho/eps - rho_rest) then gives delta p_a = K_a dt (D v_new +
// d0)_a, K_a = c0^2 / eps_a, and the pressure acceleration of that increment
// is -S1 D^T (delta p / rho^2): the transpose of the same operator, so
//   (I - dt L + dt^2 S1 D^T Q D) v_new = v* + dt (wall terms) - dt^2 S1 D^T Q d0,
// Q = diag(K_a / rho_a^2), v* = v + dt (a_ext + a_p(p_n)) the predictor. The
// matrix is symmetric positive definite whatever dt (L, the Morris operator,
// is symmetric negative semi-definite), so conjugate gradients apply, and
// the acoustic CFL limit 0.25 h / c0 is gone: sound waves longer than a step
// are damped instead of followed, which is what the weakly compressible
// fluid of the coupled models needs at small Reynolds numbers, where the
// sound speed is set by the viscous stress (Morris 1997) and not by the flow.
// The wall pressure (Adami extrapolation) stays explicit: it follows the
// fluid's new pressures at the next step. Pair forces stay antisymmetric, so
// the fluid-fluid terms conserve momentum; what the walls push is returned.
#pragma once
#include <vector>

#include <Eigen/Dense>

#include "mrf/fluid/fluid_cell.hpp"

namespace mrf {

// The terms the SPH step takes by backward Euler.
enum class SphImplicit { none, viscosity, pressure_viscosity };
const char* to_string(SphImplicit s);

struct ImplicitSolveStats {
  int iterations = 0;     // CG iterations (the three components together)
  double residual = 0;    // relative residual reached
  // sum over the fluid particles of dt x the wall accelerations (viscous and,
  // implicit, pressure) at v_new (m/s): the walls' push on the fluid over
  // the step, per unit particle mass
  Vec3 wall_dv = Vec3::Zero();
};

// The system above for one step, matrix-free: built once per step (the
// Morris weights, the pressure rows), applied in every CG iteration.
class ImplicitFluidSystem {
 public:
  ImplicitFluidSystem(const FluidCell& c, double dt, SphImplicit terms);
  // out = A x, A = I - dt L (+ dt^2 S1 D^T Q D)
  void apply(const std::vector<Vec3>& x, std::vector<Vec3>& out) const;
  // the right-hand side for the predictor v*: v* + dt (wall terms) (- dt^2 S1 D^T Q d0)
  std::vector<Vec3> rhs(const std::vector<Vec3>& v_star) const;
  // Jacobi: the diagonal of A, per component
  const std::vector<Vec3>& diagonal() const { return diag_; }
  // dt (D v + d0): the density change over the step the velocities v give
  // to first order (kg/m^3; zero rows without the pressure terms)
  std::vector<double> density_change(const std::vector<Vec3>& v) const;
  // the walls' push over the step at velocities v, per unit particle mass (m/s)
  Vec3 wall_push(const std::vector<Vec3>& v) const;
  // sum_a (A u)_a for the uniform field u = 1 e_k, column k: the fluid-fluid
  // rows cancel, what is left is I n + the wall rows (3 x 3)
  Eigen::Matrix3d uniform_response() const;

 private:
  void divergence(const std::vector<Vec3>& x, bool with_d0, std::vector<double>& s) const;  // s = D x (+ d0)
  void add_pressure(const std::vector<Vec3>& x, bool with_d0, std::vector<Vec3>& out) const;
  void scatter_pressure(std::vector<Vec3>& out) const;  // s_ *= Q, out += D^T s_ (add_pressure after the divergence)
  const FluidCell& c_;
  double dt_;
  bool pressure_;
  // Per fluid pair what apply() reads in every CG iteration, packed: its
  // two indices, -dt K (Morris) and g_ab (pressure; zero without it): one
  // 40-byte stream a product instead of the 40-byte SphPair and the weights
  // from two more arrays.
  struct Row {
    std::uint32_t a, b;
    double k;
    Vec3 g;
  };
  std::vector<Row> rows_;
  // on threads: per particle the rows it is an end of, in row order, as
  // {it, the other end, k, +-g} (CSR; empty when the products run serially)
  std::vector<std::uint32_t> inc_start_;
  std::vector<Row> inc_;
  std::vector<double> kw_, vdiag_;  // Morris: -dt K per wall pair; diagonal of I - dt L
  std::vector<Vec3> tw_, diag_;     // pressure: T_a = sum_w g_aw; Jacobi diagonal
  std::vector<double> d0_, q_;           // pressure: d0_a, dt^2 S1 K_a / rho_a^2
  mutable std::vector<double> s_;        // scratch: Q (D x + d0)
};

// Solves the system for v_new by PCG, then adds the uniform velocity that
// makes the residual sum to zero: the fluid's momentum then changes by
// exactly the walls' push (what the pair forces cancel stays cancelled,
// whatever the CG tolerance). Solves (`terms` viscosity: without the
// pressure rows; pressure_viscosity: both). `v` holds the predictor v* on
// entry (the explicit pressure of the current state in it), v_new on exit.
// Throws NumericalError when the residual of all three components together
// does not reach params.cg_tolerance of the right-hand side.
ImplicitSolveStats solve_implicit_fluid(const FluidCell& c, double dt, SphImplicit terms, std::vector<Vec3>& v);

}  // namespace mrf
