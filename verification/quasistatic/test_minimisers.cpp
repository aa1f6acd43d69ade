// The L-BFGS minimiser (quasistatic/lbfgs.hpp) and steepest descent
// (quasistatic/descent.hpp) on problems with known
// minima: an ill-conditioned chain of springs (condition number ~ n^2,
// closed-form minimum) against FIRE on the same problem, a non-convex
// Rosenbrock valley, and the failure paths (an energy inconsistent with the
// forces, the evaluation budget, a non-finite force, bad options).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "mrf/error.hpp"
#include "mrf/quasistatic/descent.hpp"
#include "mrf/quasistatic/fire.hpp"
#include "mrf/quasistatic/lbfgs.hpp"

namespace mrf {
namespace {

// n nodes on springs of stiffness k between anchors at 0 and L (each
// component), pulled by a constant force g per node: E = sum k/2 (x_{i+1} -
// x_i)^2 - g.x_i with x_0 = 0, x_{n+1} = L. Minimum: x_i = i L/(n+1) + g/(2k)
// i (n+1-i). Smallest Hessian eigenvalue k (2 - 2 cos(pi/(n+1))), largest
// about 4k: condition number ~ 4 (n+1)^2 / pi^2.
struct SpringChain {
  int n = 60;
  double k = 3.0;
  Vec3 L{1.0, 2.0, -1.0}, g{0.5, -0.25, 1.0};
  std::vector<Vec3> x, f;
  double sign = 1.0;  // -1: an energy of the wrong sign (inconsistent with the forces)

  SpringChain() : x(static_cast<std::size_t>(n)), f(static_cast<std::size_t>(n)) {
    for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = Vec3(0.3 * std::sin(i), 0.1 * i, 0.2 * std::cos(3 * i));
  }
  Vec3 node(int i) const { return i == 0 ? Vec3::Zero() : i == n + 1 ? L : x[static_cast<std::size_t>(i - 1)]; }
  double forces() {
    double e = 0;
    for (int i = 0; i <= n; ++i) e += 0.5 * k * (node(i + 1) - node(i)).squaredNorm();
    for (int i = 1; i <= n; ++i) {
      f[static_cast<std::size_t>(i - 1)] = k * (node(i + 1) - 2.0 * node(i) + node(i - 1)) + g;
      e -= g.dot(node(i));
    }
    return sign * e;
  }
  Vec3 exact(int i) const { return (double(i) / (n + 1)) * L + (0.5 / k * i * (n + 1 - i)) * g; }
  double lambda_min() const { return k * (2.0 - 2.0 * std::cos(M_PI / (n + 1))); }
  // ||x - x*||_2 <= ||f||_2 / lambda_min <= sqrt(n) max|f| / lambda_min.
  double error() const {
    double e2 = 0;
    for (int i = 1; i <= n; ++i) e2 += (node(i) - exact(i)).squaredNorm();
    return std::sqrt(e2);
  }
};

LbfgsOptions lbfgs_options(double tol) {
  LbfgsOptions o;
  o.force_tol = tol;
  o.max_evaluations = 100000;
  o.max_step = 1.0;
  o.initial_scale = 1.0 / 12.0;  // about 1 / (largest eigenvalue 4k)
  return o;
}

FireOptions fire_options(double tol) {
  FireOptions o;
  o.force_tol = tol;
  o.max_iterations = 1000000;
  o.mass = 1.0;
  const double t = 1.0 / std::sqrt(3.0);  // 1/sqrt(k); semi-implicit Euler is stable below 2/sqrt(4k)
  o.dt_max = 0.5 * t;
  o.dt_start = 0.05 * t;
  o.dt_min = 1e-3 * t;
  o.max_step = 1.0;
  return o;
}

TEST(Lbfgs, IllConditionedChainReachesTheClosedFormMinimumInFewerEvaluationsThanFire) {
  for (double tol : {1e-6, 1e-10}) {
    SpringChain a;
    const LbfgsResult l = lbfgs_minimize(a.x, a.f, lbfgs_options(tol), [&a] { return a.forces(); });
    ASSERT_TRUE(l.converged) << l.stop_reason;
    EXPECT_EQ(l.stop_reason, "converged");
    EXPECT_LT(l.max_force, tol);
    const double bound = std::sqrt(double(a.n)) * tol / a.lambda_min();
    EXPECT_LT(a.error(), bound) << "tol " << tol;
    EXPECT_EQ(l.max_force, max_force_norm(a.f));  // f is the force at the returned x
    SpringChain b;
    const FireResult fr = fire_minimize(b.x, b.f, fire_options(tol), [&b] { return b.forces(); });
    ASSERT_TRUE(fr.converged) << fr.stop_reason;
    EXPECT_LT(b.error(), bound);
    std::printf("  chain n = %d (condition %.0f), tol %.0e: L-BFGS %ld evaluations (%ld iterations, %ld resets), "
                "FIRE %ld; error %.2e and %.2e (bound %.2e)\n",
                a.n, 4.0 * a.k / a.lambda_min(), tol, l.evaluations, l.iterations, l.resets, fr.iterations + 1,
                a.error(), b.error(), bound);
    // Both grow like sqrt(condition) ln(1/tol) here (measured: L-BFGS 286
    // and 438, FIRE 569 and 774); a two-loop recursion that fell back to
    // steepest descent would need ~ condition ln(1/tol), tens of thousands.
    EXPECT_LT(l.evaluations, fr.iterations + 1);
  }
}

TEST(Lbfgs, ShortMemoryStillConverges) {
  for (int m : {1, 3}) {
    SpringChain a;
    LbfgsOptions o = lbfgs_options(1e-8);
    o.memory = m;
    const LbfgsResult l = lbfgs_minimize(a.x, a.f, o, [&a] { return a.forces(); });
    ASSERT_TRUE(l.converged) << "memory " << m << ": " << l.stop_reason;
    EXPECT_LT(a.error(), std::sqrt(double(a.n)) * 1e-8 / a.lambda_min());
  }
}

// Rosenbrock's valley in (x, y) of one particle, a quadratic well in z:
// E = (1 - x)^2 + 100 (y - x^2)^2 + z^2, minimum (1, 1, 0), non-convex.
TEST(Lbfgs, FindsTheRosenbrockMinimum) {
  std::vector<Vec3> x{Vec3(-1.2, 1.0, 0.5)}, f(1);
  const auto force = [&] {
    const double a = x[0].x(), b = x[0].y(), c = x[0].z();
    f[0] = Vec3(2.0 * (1 - a) + 400.0 * a * (b - a * a), -200.0 * (b - a * a), -2.0 * c);
    return (1 - a) * (1 - a) + 100.0 * (b - a * a) * (b - a * a) + c * c;
  };
  LbfgsOptions o = lbfgs_options(1e-9);
  o.initial_scale = 1e-3;
  o.max_step = 0.5;
  const LbfgsResult r = lbfgs_minimize(x, f, o, force);
  ASSERT_TRUE(r.converged) << r.stop_reason;
  // Hessian at the minimum has smallest eigenvalue ~0.4: |x - x*| < tol / 0.39.
  EXPECT_LT((x[0] - Vec3(1, 1, 0)).norm(), 1e-9 / 0.39);
  EXPECT_LT(r.evaluations, 200);
  std::printf("  Rosenbrock: %ld evaluations, %ld iterations, %ld resets\n", r.evaluations, r.iterations, r.resets);
}

// The line search reads the energy: an energy of the wrong sign makes every
// downhill step look uphill, so no step is accepted and the minimiser says
// so instead of returning a point that is not a minimum.
TEST(Lbfgs, EnergyInconsistentWithTheForcesFailsTheLineSearch) {
  SpringChain a;
  a.sign = -1.0;
  const LbfgsResult r = lbfgs_minimize(a.x, a.f, lbfgs_options(1e-8), [&a] { return a.forces(); });
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stop_reason, "line_search");
  EXPECT_EQ(r.iterations, 0);
}

TEST(Lbfgs, StopsAtTheEvaluationBudget) {
  SpringChain a;
  LbfgsOptions o = lbfgs_options(1e-12);
  o.max_evaluations = 7;
  const LbfgsResult r = lbfgs_minimize(a.x, a.f, o, [&a] { return a.forces(); });
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stop_reason, "max_evaluations");
  EXPECT_EQ(r.evaluations, 7);
}

TEST(Lbfgs, NonFiniteForceIsANumericalError) {
  std::vector<Vec3> x{Vec3(1, 0, 0)}, f(1);
  const auto force = [&] {
    f[0] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
    return 0.0;
  };
  EXPECT_THROW(lbfgs_minimize(x, f, lbfgs_options(1e-6), force), NumericalError);
}

// Steepest descent is the explicit Euler path of the gradient flow: on
// E = sum k_i |x_i|^2 / 2 each particle follows x_n = (1 - h k_i)^n x_0
// exactly until max |f| < tol, and it stops there; on the spring chain it
// reaches the closed-form minimum, needing more evaluations than FIRE
// (it scales with the condition number, FIRE with its square root).
TEST(Descent, FollowsTheEulerPathOfTheGradientFlowAndConverges) {
  const std::vector<double> k{1.0, 3.0, 7.0};
  std::vector<Vec3> x{Vec3(1, -2, 0.5), Vec3(0.3, 0.1, -1), Vec3(2, 2, 2)}, f(3);
  const std::vector<Vec3> x0 = x;
  const auto force = [&] {
    double e = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      f[i] = -k[i] * x[i];
      e += 0.5 * k[i] * x[i].squaredNorm();
    }
    return e;
  };
  DescentOptions o;
  o.force_tol = 1e-9;
  o.max_evaluations = 100000;
  o.step = 0.1;
  o.max_step = 10.0;  // never bites here
  const DescentResult r = descent_minimize(x, f, o, force);
  ASSERT_TRUE(r.converged) << r.stop_reason;
  const double n = static_cast<double>(r.evaluations - 1);  // steps taken
  for (std::size_t i = 0; i < x.size(); ++i)
    EXPECT_LT((x[i] - std::pow(1.0 - o.step * k[i], n) * x0[i]).norm(), 1e-12) << "particle " << i;
  // It stopped at the first step below the tolerance: one step fewer was above it.
  const double slowest = std::pow(1.0 - o.step * k[0], n - 1) * k[0] * x0[0].norm();
  EXPECT_GE(slowest, o.force_tol);
  EXPECT_LT(r.max_force, o.force_tol);

  SpringChain a;
  DescentOptions c;
  c.force_tol = 1e-6;
  c.max_evaluations = 10000000;
  c.step = 1.0 / 12.0;  // below 2 / lambda_max = 2 / (4k)
  c.max_step = 1.0;
  const DescentResult d = descent_minimize(a.x, a.f, c, [&a] { return a.forces(); });
  ASSERT_TRUE(d.converged) << d.stop_reason;
  EXPECT_LT(a.error(), std::sqrt(double(a.n)) * 1e-6 / a.lambda_min());
  SpringChain b;
  const FireResult fr = fire_minimize(b.x, b.f, fire_options(1e-6), [&b] { return b.forces(); });
  EXPECT_GT(d.evaluations, 5 * (fr.iterations + 1));
  std::printf("  chain: steepest descent %ld evaluations, FIRE %ld\n", d.evaluations, fr.iterations + 1);
  c.max_evaluations = 10;
  SpringChain e;
  const DescentResult short_run = descent_minimize(e.x, e.f, c, [&e] { return e.forces(); });
  EXPECT_FALSE(short_run.converged);
  EXPECT_EQ(short_run.stop_reason, "max_evaluations");
  EXPECT_EQ(short_run.evaluations, 10);
}

TEST(Lbfgs, BadOptionsNameTheirKey) {
  const auto key_of = [](LbfgsOptions o) {
    try {
      o.validate("q.");
    } catch (const InputError& e) {
      return e.key();
    }
    return std::string("none");
  };
  LbfgsOptions o = lbfgs_options(1e-6);
  EXPECT_EQ(key_of(o), "none");
  o.memory = 0;
  EXPECT_EQ(key_of(o), "q.memory");
  o = lbfgs_options(1e-6);
  o.c2 = o.c1;
  EXPECT_EQ(key_of(o), "q.c2");
  o = lbfgs_options(1e-6);
  o.initial_scale = 0;
  EXPECT_EQ(key_of(o), "q.initial_scale");
}

}  // namespace
}  // namespace mrf
