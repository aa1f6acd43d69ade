// The quasi-static driver (quasistatic/aqs.hpp): a Hertz pair under the
// known load of its own dipole attraction relaxes to the closed-form overlap
// (F/k)^{2/3} within the bound the force tolerance sets; on the small scene
// every accepted minimum is below the tolerance and its wall and virial
// stresses agree within N (gap/2) force_tol / V (static equilibrium); a
// minimisation that cannot converge stops the run with a NumericalError.
// Both for FIRE and L-BFGS (the Hertz pair also for steepest descent).
// Checkpoints, branches and --start-from: test_aqs_resume.cpp.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>

#include "mrf/error.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/quasistatic/aqs.hpp"
#include "support/iron_pair.hpp"
#include "smoke_options.hpp"
#include "support/small_scene.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, M = 1e6;

using test::smoke_options;

SceneConfig pair_config() { return test::iron_pair_config(R, M, 15e-6); }

// Two free spheres, no walls, started apart and off the field axis: they
// turn into the field, meet head-to-tail and compress until Hertz carries
// the dipole load F(2R - h) of the shifted-force law. The closed form
// h = (F/k)^{2/3} with F at the final separation is solved by fixed point.
// At an accepted minimum |k h^{3/2} - F| < tol on each sphere, so
// |h - h*| < tol / (dF_net/dh) = tol / (k_eff - |dF/dr|). Both minimisers.
class QuasistaticHertz : public ::testing::TestWithParam<Minimiser> {};

TEST_P(QuasistaticHertz, PairRelaxesToClosedFormOverlap) {
  const DemParams p = dem_params(pair_config());
  const double rc = p.dipole_cutoff, k = p.hertz_k;
  const auto load = [&](double h) { return -shifted_dipole_force_x(Vec3(2 * R - h, 0, 0), p.dipole_pref, rc).x(); };
  double h_star = hertz_overlap_under_load(load(0), k);
  for (int i = 0; i < 50; ++i) h_star = hertz_overlap_under_load(load(h_star), k);
  const double dfdr = (load(h_star + 1e-12) - load(h_star - 1e-12)) / 2e-12;  // dF/dh = -dF/dr
  const double stiffness = hertz_local_stiffness(h_star, k) - dfdr;
  for (double tol : {1e-4, 1e-7, 1e-10}) {
    ShearCell cell;
    cell.box = Box{100e-6, 40e-6, 40e-6};
    cell.free.x = {Vec3(-1.3 * R, 20e-6, 20e-6), Vec3(1.3 * R, 20e-6, 20e-6 + 0.3 * R)};
    QuasistaticOptions o;
    o.force_tol = tol;
    o.minimiser = GetParam();
    o.max_iterations = 20000000;
    const MinimiserOptions m = quasistatic_minimiser_options(p, o);
    const double force_tol = m.force_tol();
    QuasistaticState s = make_quasistatic_state(cell, p, rc);
    const Relaxation r = relax(s, m, 0, 0.0);
    ASSERT_TRUE(r.converged);
    const QuasistaticPoint pt = measure(s);
    EXPECT_LT(pt.max_force, force_tol);
    const Vec3 d = s.cell.free.x[1] - s.cell.free.x[0];
    const double h = 2 * R - d.norm();
    EXPECT_NEAR(h, pt.max_overlap, 1e-15);
    const double bound = force_tol / stiffness;
    EXPECT_NEAR(h, h_star, bound) << "tol " << tol << " after " << r.iterations << " iterations";
    EXPECT_LT(std::abs(d.z()) + std::abs(d.y()), 1e-3 * R + 2 * R * force_tol / load(h_star));  // aligned
    std::printf("  %s, tol %.0e F0: h = %.9e m, h* = %.9e m, |h-h*| = %.2e m (bound %.2e), %ld iterations\n", minimiser_name(GetParam()), tol, h,
                h_star, std::abs(h - h_star), bound, r.iterations);
  }
}

std::string param_name(const ::testing::TestParamInfo<Minimiser>& p) { return minimiser_name(p.param); }
INSTANTIATE_TEST_SUITE_P(Minimisers, QuasistaticHertz,
                         ::testing::Values(Minimiser::fire, Minimiser::lbfgs, Minimiser::descent), param_name);

// numerics.threads holds for the driver as for `mrf run` (it once did not:
// every quasi-static run took all cores, on a machine shared with sweeps).
TEST(Quasistatic, TakesTheScenesThreadCount) {
  const int before = omp_get_max_threads();
  for (int threads : {3, 1}) {
    (void)quasistatic_run(test::scene({"numerics.threads=" + std::to_string(threads)}), QuasistaticOptions{});
    EXPECT_EQ(omp_get_max_threads(), threads);
  }
  omp_set_num_threads(before);
}


// The small scene (375 spheres): the initial minimum from the random packing
// and five increments; every accepted minimum is below the tolerance and in
// static equilibrium. FIRE's iterations grow with the contact stiffness
// (k_eff ~ Y^{2/3}, iterations ~ sqrt of the stiffness ratio): the fast case
// runs at Y/100 (max overlap ~ 7e-3 R, REFERENCE §8), the slow one at the
// scene's 200 GPa.
void smoke_run(const std::vector<std::string>& overrides, Minimiser minimiser = Minimiser::fire) {
  const LoadedScene scene = test::scene(overrides);
  QuasistaticOptions o = smoke_options();
  o.minimiser = minimiser;
  std::size_t seen = 0;
  const QuasistaticResult r = run_quasistatic(scene, o, [&](const QuasistaticPoint& pt) {
    EXPECT_EQ(pt.increment, seen++);
    EXPECT_LT(pt.max_force, o.force_tol * dipole_contact_force(R, M));
  });
  ASSERT_EQ(r.strain.size(), 6u);
  ASSERT_EQ(seen, 6u);
  EXPECT_EQ(r.final_cell.free.size(), 375u);
  EXPECT_NEAR(r.force_tol, o.force_tol * dipole_contact_force(R, M), 1e-20);
  const double scale = r.stress_scale;  // phi mu0 M^2
  EXPECT_NEAR(scale, 0.3 * k_mu0 * M * M, 0.01 * scale);
  for (std::size_t k = 0; k < r.strain.size(); ++k) {
    EXPECT_NEAR(r.strain[k], 1e-3 * static_cast<double>(k), 1e-15);
    EXPECT_LT(r.max_force[k], r.force_tol);
    EXPECT_LE(std::abs(r.stress_wall[k] - r.stress_virial[k]), r.equilibrium_bound) << "increment " << k;
    EXPECT_NEAR(r.stress_virial[k], r.stress_virial_magnetic[k] + r.stress_virial_contact[k], 1e-12 * scale);
    EXPECT_TRUE(std::isfinite(r.energy[k]));
    EXPECT_LT(r.energy[k], 0.0);           // chains: the dipole energy dominates
    EXPECT_GT(r.max_overlap[k], 0.0);      // touching spheres
    EXPECT_LT(r.max_overlap[k], 2e-2 * R); // REFERENCE §8: h/R <~ 1-2 %
    EXPECT_GE(r.iterations[k], 0);
  }
  EXPECT_GT(r.iterations[0], 100);  // the random packing is far from a minimum
  EXPECT_GT(r.steady_wall.samples, 0);
  std::printf("  small scene, %s: %.2f s, %ld force evaluations, %ld list builds; iterations per minimum:", minimiser_name(minimiser), r.wall_seconds,
              r.force_evaluations, r.list_builds);
  for (long it : r.iterations) std::printf(" %ld", it);
  std::printf("\n  stress (Pa): wall");
  for (double t : r.stress_wall) std::printf(" %.2f", t);
  std::printf("; virial");
  for (double t : r.stress_virial) std::printf(" %.2f", t);
  std::printf("; |wall - virial| bound %.3g Pa; phi mu0 M^2 = %.4g Pa; max overlap / R %.2e\n", r.equilibrium_bound,
              scale, r.max_overlap.back() / R);
}

TEST(QuasistaticSmallScene, SmokeAndInvariantsReducedModulus) { smoke_run({"contact.youngs_modulus=\"2 GPa\""}); }

TEST(QuasistaticSmallScene, SmokeAndInvariantsReducedModulusLbfgs) {
  smoke_run({"contact.youngs_modulus=\"2 GPa\""}, Minimiser::lbfgs);
}

TEST(QuasistaticSmallScene, SlowSmokeAndInvariantsRealModulus) { smoke_run({}); }

TEST(QuasistaticSmallScene, SlowSmokeAndInvariantsRealModulusLbfgs) { smoke_run({}, Minimiser::lbfgs); }

TEST(QuasistaticSmallScene, UnconvergedMinimisationStopsTheRun) {
  QuasistaticOptions o = smoke_options();
  o.max_iterations = 50;
  try {
    run_quasistatic(test::scene(), o);
    FAIL() << "no error";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("increment 0"), std::string::npos) << what;
    EXPECT_NE(what.find("quasistatic.max_iterations"), std::string::npos) << what;
  }
}

TEST(QuasistaticOptions, BadValuesNameTheirKey) {
  const auto key_of = [](QuasistaticOptions o) {
    try {
      o.validate();
    } catch (const InputError& e) {
      return e.key();
    }
    return std::string("none");
  };
  QuasistaticOptions o;
  EXPECT_EQ(key_of(o), "none");
  o.strain_increment = 0;
  EXPECT_EQ(key_of(o), "quasistatic.strain_increment");
  o = {};
  o.force_tol = -1;
  EXPECT_EQ(key_of(o), "quasistatic.force_tol");
  o = {};
  o.strain = 1.0;
  o.warmup_strain = 2.0;
  EXPECT_EQ(key_of(o), "quasistatic.warmup_strain");
  o = {};
  o.max_iterations = 0;
  EXPECT_EQ(key_of(o), "quasistatic.max_iterations");
  o = {};
  o.lbfgs_memory = 0;
  EXPECT_EQ(key_of(o), "quasistatic.lbfgs_memory");
  try {
    (void)parse_minimiser("cg", "--minimiser");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "--minimiser");
    EXPECT_NE(std::string(e.what()).find("fire, lbfgs or descent"), std::string::npos) << e.what();
  }
  // a cut-off beyond the minimum image of the small box (32 um)
  o = smoke_options();
  o.dipole_cutoff = 20e-6;
  try {
    run_quasistatic(test::scene(), o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "quasistatic.dipole_cutoff");
  }
  // no magnetisation, no force scale
  try {
    run_quasistatic(test::scene({"particles.magnetization=0", "drive.shear_rate=100"}), smoke_options());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "particles.magnetization");
  }
}

}  // namespace
}  // namespace mrf

namespace mrf {
namespace {

// The orbit detector on synthetic series: a transient followed by an exact
// sawtooth of period 7 is periodic and its mean is the sawtooth's; noise of
// 1e-3 is not periodic; a series shorter than two periods reports none.
TEST(QuasistaticOrbit, FindsAnExactPeriodAndItsMeanAndRejectsNoise) {
  std::vector<double> y;
  for (int k = 0; k < 20; ++k) y.push_back(50.0 - k);  // transient
  const double saw[7] = {10, 12, 14, 16, 18, 20, 5};
  for (int rep = 0; rep < 5; ++rep)
    for (double v : saw) y.push_back(v);
  const OrbitMean o = orbit_mean(y, 20, 7, 1e-6);
  EXPECT_TRUE(o.periodic);
  EXPECT_EQ(o.period, 7u);
  EXPECT_DOUBLE_EQ(o.mean, 95.0 / 7.0);
  EXPECT_EQ(o.deviation, 0.0);
  // A wrong period is not accepted.
  EXPECT_FALSE(orbit_mean(y, 20, 6, 1e-6).periodic);
  std::vector<double> noisy = y;
  for (std::size_t k = 20; k < noisy.size(); ++k) noisy[k] *= 1.0 + 1e-3 * std::sin(static_cast<double>(k));
  const OrbitMean n = orbit_mean(noisy, 20, 7, 1e-6);
  EXPECT_FALSE(n.periodic);
  EXPECT_GT(n.deviation, 1e-4);
  EXPECT_EQ(orbit_mean(y, 20, 20, 1e-6).period, 0u);
}

}  // namespace
}  // namespace mrf
