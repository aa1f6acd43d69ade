// The implicit inertialess integrator (contacts backward Euler or BDF2,
// dipole and flow explicit; scene/dem_model.hpp) against SUNDIALS CVODE
// (BDF, dense direct solver, rtol 1e-11) on the same ODE
//   dx_i/dt = u(x_i) + (F_dipole + F_hertz)_i / gamma,
// with the wall spheres moving at (0, 0, gdot x_wall):
//  (a) TEST 1.2 pair: two iron spheres at 8 um head-to-tail attract and stop in
//      Hertz contact (Y = 200 GPa);
//  (b) a chain of ten spheres spanning the gap, released in a zigzag, settling
//      and tilting under shear.
// Fixed steps of the implicit scheme, order 1 (IMEX Euler) and 2 (IMEX BDF2);
// the observed order is fitted (GSL) and asserted. Steps are 10-300 times the explicit contact limits, where explicit
// schemes are unstable. (d) stability at 100x the explicit limits, overlap
// bounded by the static Hertz overlap under the chain load.
#include <cvode/cvode.h>
#include <gtest/gtest.h>

#include "support/cvode_handles.hpp"
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "mrf/error.hpp"
#include "mrf/forces/dipole.hpp"
#include "mrf/forces/drag.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/scene/dem_model.hpp"
#include "support/cvode_pair.hpp"
#include "support/fit_order.hpp"

namespace mrf {
namespace {

using Positions = std::vector<Vec3>;

struct Problem {
  DemParams p;
  Box box;
  Positions x0;
  WallParticles walls;  // at t = 0
};

// Non-drag forces (N) by brute force over all pairs, walls at time t (s).
Positions forces(const Problem& pb, const Positions& x, double t) {
  const DemParams& p = pb.p;
  Positions f(x.size(), Vec3::Zero());
  const double two_r = 2 * p.radius;
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t k = i + 1; k < x.size(); ++k) {
      const Vec3 r_ik = pb.box.min_image(x[i] - x[k]);
      Vec3 fi = hertz_pair_force(r_ik, two_r, p.hertz_k);
      if (r_ik.squaredNorm() < p.dipole_cutoff * p.dipole_cutoff) fi += dipole_force_x(r_ik, p.dipole_pref);
      f[i] += fi;
      f[k] -= fi;
    }
    for (const Vec3& w0 : pb.walls.x) {
      const Vec3 w = w0 + Vec3(0, 0, p.shear_rate * w0.x() * t);
      f[i] += hertz_pair_force(pb.box.min_image(x[i] - w), two_r, p.hertz_k);
    }
  }
  return f;
}

void check(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string(call) + " returned " + std::to_string(flag));
}

int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
  const auto* pb = static_cast<const Problem*>(user);
  const double* s = N_VGetArrayPointer(y);
  double* ds = N_VGetArrayPointer(ydot);
  Positions x(pb->x0.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = Vec3(s[3 * i], s[3 * i + 1], s[3 * i + 2]);
  const Positions f = forces(*pb, x, t);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3 v = couette_velocity(x[i], pb->p.shear_rate) + f[i] / pb->p.gamma;
    for (int d = 0; d < 3; ++d) ds[3 * i + static_cast<std::size_t>(d)] = v[d];
  }
  return 0;
}

// CVODE BDF with a dense direct solver (difference-quotient Jacobian).
std::vector<Positions> cvode_reference(const Problem& pb, const std::vector<double>& t_out, double rtol) {
  test::CvodeHandles h;
  const auto n = static_cast<sunindextype>(3 * pb.x0.size());
  check(SUNContext_Create(nullptr, &h.ctx), "SUNContext_Create");
  h.y = N_VNew_Serial(n, h.ctx);
  double* y = N_VGetArrayPointer(h.y);
  for (std::size_t i = 0; i < pb.x0.size(); ++i)
    for (int d = 0; d < 3; ++d) y[3 * i + static_cast<std::size_t>(d)] = pb.x0[i][d];
  h.mem = CVodeCreate(CV_BDF, h.ctx);
  check(CVodeInit(h.mem, rhs, 0.0, h.y), "CVodeInit");
  check(CVodeSStolerances(h.mem, rtol, rtol * pb.p.radius), "CVodeSStolerances");
  check(CVodeSetUserData(h.mem, const_cast<Problem*>(&pb)), "CVodeSetUserData");
  h.a = SUNDenseMatrix(n, n, h.ctx);
  h.ls = SUNLinSol_Dense(h.y, h.a, h.ctx);
  check(CVodeSetLinearSolver(h.mem, h.ls, h.a), "CVodeSetLinearSolver");
  check(CVodeSetMaxNumSteps(h.mem, 10'000'000), "CVodeSetMaxNumSteps");
  std::vector<Positions> out;
  for (double t_stop : t_out) {
    check(CVodeSetStopTime(h.mem, t_stop), "CVodeSetStopTime");
    sunrealtype t = 0;
    check(CVode(h.mem, t_stop, h.y, &t, CV_NORMAL), "CVode");
    Positions x(pb.x0.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = Vec3(y[3 * i], y[3 * i + 1], y[3 * i + 2]);
    out.push_back(x);
  }
  return out;
}

struct ImplicitRun {
  std::vector<Positions> x;
  double wall_s = 0, max_overlap = 0;
  long steps = 0;
  ImplicitCounters counters;
};

ImplicitRun run_implicit(const Problem& pb, double dt, const std::vector<double>& t_out, int order) {
  ShearCell cell{pb.box, {pb.x0, Positions(pb.x0.size(), Vec3::Zero()), Positions(pb.x0.size(), Vec3::Zero())},
                 pb.walls};
  const auto start = std::chrono::steady_clock::now();
  DemModel m(std::move(cell), pb.p, IntegratorId::implicit, dt);
  ImplicitOptions o;
  o.fixed_step = true;
  o.order = order;
  o.newton_tol_over_radius = 1e-10;  // far below the discretisation errors measured
  o.linear_rtol = 1e-12;
  m.set_implicit_options(o);
  ImplicitRun run;
  for (double t : t_out) {
    const long n = std::lround(t / dt);
    if (std::abs(static_cast<double>(n) * dt - t) > 1e-9 * t) throw std::invalid_argument("t not a multiple of dt");
    while (m.steps() < n) {
      m.step();
      run.max_overlap = std::max(run.max_overlap, m.sums().max_overlap);
    }
    run.x.push_back(m.cell().free.x);
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.steps = m.steps();
  run.counters = m.implicit_counters();
  return run;
}

double max_error(const Problem& pb, const std::vector<Positions>& a, const std::vector<Positions>& b) {
  double e = 0;
  for (std::size_t j = 0; j < a.size(); ++j)
    for (std::size_t i = 0; i < a[j].size(); ++i) e = std::max(e, pb.box.min_image(a[j][i] - b[j][i]).norm());
  return e;
}

std::vector<double> grid(double step, double t_end) {
  std::vector<double> t;
  for (long n = 1; static_cast<double>(n) * step <= t_end * (1 + 1e-12); ++n) t.push_back(static_cast<double>(n) * step);
  return t;
}

// Fixed-step runs at dt0 / 2^l against the reference; returns the fitted order.
double observed_order(const Problem& pb, double dt0, int levels, double out_step, double t_end, const char* name,
                      int order) {
  const std::vector<double> t = grid(out_step, t_end);
  const std::vector<Positions> ref = cvode_reference(pb, t, 1e-11);
  std::vector<double> dt, err;
  for (int l = 0; l < levels; ++l) {
    dt.push_back(dt0 / std::pow(2.0, l));
    const ImplicitRun run = run_implicit(pb, dt.back(), t, order);
    err.push_back(max_error(pb, run.x, ref));
    std::printf("%s dt %.3e  error %.4e m (%.3e R)  wall %.4f s  %ld steps  %ld Newton  %ld CG\n", name, dt.back(),
                err.back(), err.back() / pb.p.radius, run.wall_s, run.steps, run.counters.newton_iterations,
                run.counters.linear_iterations);
    if (l > 0) {
      EXPECT_LT(err[static_cast<std::size_t>(l)], err[static_cast<std::size_t>(l - 1)]) << name << " level " << l;
    }
  }
  const test::OrderFit fit = test::fit_order(dt, err);
  std::printf("%s observed order %.4f +- %.4f\n", name, fit.order, fit.stderr_order);
  return fit.order;
}

// ---- (a) the TEST 1.2 pair, head-to-tail, into Hertz contact.
Problem pair_problem() {
  const test::PairProblem pp = test::iron_pair(8e-6, 0.0);
  return {pp.params, pp.box, {pp.x0[0], pp.x0[1]}, {}};
}

TEST(ImplicitVsCvode, PairIntoHertzContactIsFirstOrder) {
  const Problem pb = pair_problem();
  // Contact at 5.43e-6 s (TEST 1.2), at rest by 8e-6 s. The explicit
  // overdamped limit in contact is gamma/k_eff = 6.5e-10 s; dt = 8e-8 .. 1e-8 s.
  const double limit = contact_limit_at_overlap(pb.p, IntegratorId::overdamped,
                                                hertz_overlap_under_load(pb.p.contact_force, pb.p.hertz_k));
  std::printf("explicit overdamped contact limit %.3e s\n", limit);
  ASSERT_GT(8e-8 / 8, 10 * limit);
  EXPECT_NEAR(observed_order(pb, 8e-8, 4, 8e-8, 8e-6, "pair", 1), 1.0, 0.15);
}

TEST(ImplicitVsCvode, PairIntoHertzContactBdf2) {
  const Problem pb = pair_problem();
  const double order = observed_order(pb, 8e-8, 4, 8e-8, 8e-6, "pair BDF2", 2);
  EXPECT_NEAR(order, 2.0, 0.2);
}

TEST(ImplicitVsCvode, PairComesToRestAtTheStaticOverlap) {
  // Backward Euler keeps the equilibria of the ODE exactly: at rest the
  // overlap is the reference's to the Newton tolerance, at any step.
  const Problem pb = pair_problem();
  const std::vector<double> t{12e-6};
  const Positions ref = cvode_reference(pb, t, 1e-12)[0];
  const ImplicitRun run = run_implicit(pb, 1e-7, t, 2);
  const double h_ref = 2 * pb.p.radius - (ref[1] - ref[0]).norm();
  const double h = 2 * pb.p.radius - (run.x[0][1] - run.x[0][0]).norm();
  std::printf("static overlap: implicit %.10e m, CVODE %.10e m\n", h, h_ref);
  EXPECT_NEAR(h / h_ref, 1.0, 1e-6);
}

// ---- (b) a gap-spanning chain of ten spheres under shear.
// Walls of spheres at spacing R; the chain's centres evenly spread in x
// between the wall contacts, in a zigzag of y = +-zigzag.
Problem chain_problem(double shear_rate, double gap_over_radius, double zigzag_over_radius) {
  SceneConfig c;
  c.radius = 2.5e-6;
  c.density = 7800;
  c.magnetization = 1e6;
  c.viscosity = 0.1;
  c.youngs_modulus = 200e9;
  c.poisson_ratio = 0.3;
  c.dipole_cutoff = 7 * c.radius;  // chain neighbours at 2, 4, 6 R inside, 8 R outside
  c.shear_rate = shear_rate;
  c.gap = gap_over_radius * c.radius;
  c.ly = c.lz = 40e-6;
  Problem pb{dem_params(c), Box{c.gap, c.ly, c.lz}, {}, {}};
  pb.walls = build_walls(pb.box, c.radius);
  const double x_lo = -0.5 * c.gap + 2 * c.radius, x_hi = -x_lo;
  for (int j = 0; j < 10; ++j)
    pb.x0.emplace_back(x_lo + (x_hi - x_lo) * j / 9.0, 0.5 * c.ly + (j % 2 ? 1 : -1) * zigzag_over_radius * c.radius,
                       0.5 * c.lz + 0.3 * c.radius);
  return pb;
}

// Mn = 1e-2 (gdot = 2.79e4 1/s), gap 22R - 0.002R (the straight chain is
// pressed slightly against the walls), zigzag 0.25 R.
TEST(ImplicitVsCvode, ShearedTenSphereChainIsFirstOrder) {
  const Problem pb = chain_problem(2.7925e4, 22 - 0.002, 0.25);
  const double h = hertz_overlap_under_load(pb.p.contact_force, pb.p.hertz_k);
  std::printf("explicit contact limits at the pair overlap: overdamped %.3e s, verlet_exp %.3e s\n",
              contact_limit_at_overlap(pb.p, IntegratorId::overdamped, h),
              contact_limit_at_overlap(pb.p, IntegratorId::verlet_exp, h));
  EXPECT_NEAR(observed_order(pb, 2e-8, 4, 1e-7, 4e-6, "chain", 1), 1.0, 0.15);
}

// BDF2 on the chain: the Hertz force h^{3/2} has an unbounded second
// derivative where a contact closes, and the chain's zigzag closes several,
// so the observed order falls between 1 and 2 (1.45 +- 0.13 measured; the
// single pair, with one closing, gives 1.92); the error is 8-19x below
// order 1's at the same steps.
TEST(ImplicitVsCvode, ShearedTenSphereChainBdf2) {
  const Problem pb = chain_problem(2.7925e4, 22 - 0.002, 0.25);
  const double order = observed_order(pb, 2e-8, 4, 1e-7, 4e-6, "chain BDF2", 2);
  EXPECT_GT(order, 1.3);
  EXPECT_LT(order, 2.2);
}

// ---- (d) stability far above the explicit contact limits, Y = 200 GPa.
// A straight chain (gaps of 1e-3 R, gap 22.01 R) at Mn = 1e-4 closes, settles
// and tilts slowly; fixed steps of k_multiple times the larger explicit
// contact limit (verlet_exp, at the static overlap of a pair), which is over
// 100x the explicit inertialess (overdamped) limit. Much larger steps fail
// for another reason: the explicit dipole force (stiffness ~ 4 F/r) moves a
// particle more than the contact margin per step near dt ~ 1e-6 s. The largest overlap must lie between the static overlap of
// a single head-to-tail pair and that under the design load of the scene
// (expected_contact_load: 2 zeta(3) times the pair force plus the drag on a
// gap-spanning chain, REFERENCE §1, §2), and match CVODE at the end.
constexpr double k_multiple = 10;
TEST(ImplicitStability, ChainFarAboveTheExplicitLimitsStaysFiniteWithBoundedOverlap) {
  const Problem pb = chain_problem(2.7925e2, 22 + 0.01, 0.0);
  const DemParams& p = pb.p;
  const double h_pair = hertz_overlap_under_load(p.contact_force, p.hertz_k);
  const double h_design = hertz_overlap_under_load(2 * 1.2020569 * p.contact_force +
                                                       p.gamma * p.shear_rate * pb.box.gap * pb.box.gap / (16 * p.radius),
                                                   p.hertz_k);
  const double limit_ve = contact_limit_at_overlap(p, IntegratorId::verlet_exp, h_pair);
  const double limit_od = contact_limit_at_overlap(p, IntegratorId::overdamped, h_pair);
  const double dt = k_multiple * limit_ve;
  std::printf("dt = %.0f x the verlet_exp limit = %.0f x the overdamped limit\n", dt / limit_ve, dt / limit_od);
  ASSERT_GE(dt, 100 * limit_od);
  const std::vector<double> t{200 * dt};
  const Positions ref = cvode_reference(pb, t, 1e-10)[0];
  // Sharper: the middle contact of a straight chain of ten carries the pairs
  // across it within the cut-off 7R: 1 + 2/2^4 + 3/3^4 pair forces.
  const double h_chain = hertz_overlap_under_load((1 + 2 / 16.0 + 3 / 81.0) * p.contact_force, p.hertz_k);
  for (int order : {1, 2}) {
    const ImplicitRun run = run_implicit(pb, dt, t, order);
    for (const Vec3& x : run.x[0]) ASSERT_TRUE(x.allFinite());
    std::printf("order %d, dt %.3e s; max overlap %.4e m (pair %.4e, static chain %.4e, design %.4e); end error %.3e R\n",
                order, dt, run.max_overlap, h_pair, h_chain, h_design, max_error(pb, run.x, {ref}) / p.radius);
    EXPECT_GT(run.max_overlap, h_pair) << order;
    EXPECT_LT(run.max_overlap, h_design) << order;
    // Backward Euler approaches the static overlap from below; BDF2 is not
    // monotone and overshoots it in the closing transient (9 % here).
    if (order == 1) {
      EXPECT_NEAR(run.max_overlap / h_chain, 1.0, 0.01) << "static chain overlap " << h_chain;
    }
    EXPECT_LT(max_error(pb, run.x, {ref}), 1e-3 * p.radius) << order;  // settled: both at the same equilibrium
  }
}

// A fixed step far beyond what the explicit dipole force and the contact
// margin allow (1e-5 s: the zigzag chain would move by several R) stops with
// a NumericalError that names the step and a particle, before any NaN.
TEST(ImplicitStability, OversizedFixedStepStopsWithAClearError) {
  const Problem pb = chain_problem(2.7925e4, 22 - 0.002, 0.25);
  try {
    run_implicit(pb, 1e-5, {1e-5}, 2);
    ADD_FAILURE() << "no NumericalError";
  } catch (const NumericalError& e) {
    const std::string msg = e.what();
    std::printf("%s\n", msg.c_str());
    EXPECT_NE(msg.find("at step 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("particle"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace mrf
