// The quasi-static driver (quasistatic/aqs.hpp): a Hertz pair under the
// known load of its own dipole attraction relaxes to the closed-form overlap
// (F/k)^{2/3} within the bound the force tolerance sets; on the small scene
// every accepted minimum is below the tolerance and its wall and virial
// stresses agree within N (gap/2) force_tol / V (static equilibrium); a
// minimisation that cannot converge stops the run with a NumericalError.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "mrf/error.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/quasistatic/aqs.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/io/archive.hpp"
#include "support/files.hpp"
#include "support/iron_pair.hpp"
#include "support/small_scene.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, M = 1e6;

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

QuasistaticOptions smoke_options() {
  QuasistaticOptions o;
  o.strain_increment = 1e-3;
  o.strain = 5e-3;
  o.warmup_strain = 0.0;
  o.force_tol = 1e-6;
  return o;
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

// A plain load of a checkpoint written with other options is refused, naming the option.
void expect_refused(const LoadedScene& scene, const QuasistaticOptions& o, const std::string& ckpt,
                    const std::string& key) {
  QuasistaticRun refused = quasistatic_run(scene, o);
  try {
    ArchiveReader in(ckpt);
    refused.load(in);
    FAIL() << "no error";
  } catch (const NumericalError& err) {
    EXPECT_NE(std::string(err.what()).find(key), std::string::npos) << err.what();
  }
}

// A run checkpointed after two minima and restored into a fresh run of
// the same scene continues bit for bit: the same minima, iterations and
// stresses as the run that never stopped; a larger total strain extends a
// finished run; a checkpoint of another increment is refused by name.
TEST(QuasistaticResume, RestoredRunContinuesBitForBitAndExtends) {
  const LoadedScene scene = test::scene({"contact.youngs_modulus=\"2 GPa\""});
  QuasistaticOptions o = smoke_options();
  o.strain = 3e-3;  // a coarse tolerance and few increments: the test is the continuation, not the physics
  o.force_tol = 1e-4;
  test::TempDir dir("aqs_resume");
  const std::string ckpt = (dir.path() / "checkpoint.bin").string();
  QuasistaticRun first = quasistatic_run(scene, o);  // the run that never stops, saved on the way
  for (int k = 0; k < 2; ++k) first.step();
  {
    ArchiveWriter w(ckpt);
    first.save(w);
    w.close();
  }
  while (!first.done()) first.step();
  const QuasistaticResult straight = first.finish();
  QuasistaticRun resumed = quasistatic_run(scene, o);
  {
    ArchiveReader in(ckpt);
    resumed.load(in);
    in.expect_end();
  }
  EXPECT_EQ(resumed.next_increment(), 2u);
  while (!resumed.done()) resumed.step();
  const QuasistaticResult r = resumed.finish();
  ASSERT_EQ(r.strain.size(), straight.strain.size());
  for (std::size_t k = 0; k < r.strain.size(); ++k) {
    EXPECT_EQ(r.stress_wall[k], straight.stress_wall[k]) << "minimum " << k;
    EXPECT_EQ(r.stress_virial[k], straight.stress_virial[k]) << "minimum " << k;
    EXPECT_EQ(r.energy[k], straight.energy[k]) << "minimum " << k;
    EXPECT_EQ(r.iterations[k], straight.iterations[k]) << "minimum " << k;
  }
  EXPECT_EQ(r.force_evaluations, straight.force_evaluations);
  for (std::size_t i = 0; i < r.final_cell.free.size(); ++i)
    ASSERT_EQ(r.final_cell.free.x[i], straight.final_cell.free.x[i]) << "particle " << i;

  // Extension: the checkpoint of two minima resumed with a larger strain.
  QuasistaticOptions longer = o;
  longer.strain = 4e-3;
  QuasistaticRun extended = quasistatic_run(scene, longer);
  {
    ArchiveReader in(ckpt);
    extended.load(in);
  }
  while (!extended.done()) extended.step();
  const QuasistaticResult e = extended.finish();
  ASSERT_EQ(e.strain.size(), 5u);
  for (std::size_t k = 0; k < straight.strain.size(); ++k) EXPECT_EQ(e.stress_wall[k], straight.stress_wall[k]);
  EXPECT_NEAR(e.strain.back(), 4e-3, 1e-15);

  QuasistaticOptions other = o;
  other.strain_increment = 5e-4;
  expect_refused(scene, other, ckpt, "quasistatic.strain_increment");
  other = o;
  other.minimiser = Minimiser::lbfgs;
  expect_refused(scene, other, ckpt, "quasistatic.minimiser");
}

// A branch (load with branch = true) takes another run's checkpoint at
// another force tolerance: the minima before it are that run's, every later
// one meets the branch's tolerance, and a branch at the same tolerance
// continues the run bit for bit. Without branch the tolerance is refused.
TEST(QuasistaticResume, BranchAtAnotherToleranceStartsFromTheSameMinimum) {
  const LoadedScene scene = test::scene({"contact.youngs_modulus=\"2 GPa\""});
  QuasistaticOptions o = smoke_options();
  o.strain = 3e-3;
  o.force_tol = 1e-4;
  test::TempDir dir("aqs_branch");
  const std::string ckpt = (dir.path() / "checkpoint.bin").string();
  QuasistaticRun parent = quasistatic_run(scene, o);
  for (int k = 0; k < 2; ++k) parent.step();
  {
    ArchiveWriter w(ckpt);
    parent.save(w);
    w.close();
  }
  while (!parent.done()) parent.step();
  const QuasistaticResult straight = parent.finish();
  auto branch = [&](double tol) {
    QuasistaticOptions b = o;
    b.force_tol = tol;
    QuasistaticRun run = quasistatic_run(scene, b);
    ArchiveReader in(ckpt);
    run.load(in, true);
    in.expect_end();
    EXPECT_EQ(run.next_increment(), 2u);
    while (!run.done()) run.step();
    return run.finish();
  };
  const QuasistaticResult same = branch(o.force_tol);
  ASSERT_EQ(same.strain.size(), straight.strain.size());
  for (std::size_t k = 0; k < same.strain.size(); ++k) EXPECT_EQ(same.stress_wall[k], straight.stress_wall[k]) << k;
  const QuasistaticResult tight = branch(1e-6);
  ASSERT_EQ(tight.strain.size(), straight.strain.size());
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(tight.stress_wall[k], straight.stress_wall[k]) << "minimum " << k;
  for (std::size_t k = 2; k < tight.strain.size(); ++k) {
    EXPECT_LT(tight.max_force[k], 1e-6 * tight.force_scale) << "minimum " << k;
    EXPECT_NE(tight.stress_wall[k], straight.stress_wall[k]) << "minimum " << k << ": the tolerance must matter";
  }
  QuasistaticOptions t = o;
  t.force_tol = 1e-6;
  expect_refused(scene, t, ckpt, "quasistatic.force_tol");

  // A branch may also change the minimiser: L-BFGS goes on from FIRE's
  // second minimum, and every later minimum meets the tolerance.
  QuasistaticOptions l = o;
  l.minimiser = Minimiser::lbfgs;
  QuasistaticRun run = quasistatic_run(scene, l);
  {
    ArchiveReader in(ckpt);
    run.load(in, true);
    in.expect_end();
  }
  while (!run.done()) run.step();
  const QuasistaticResult lb = run.finish();
  ASSERT_EQ(lb.strain.size(), straight.strain.size());
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(lb.stress_wall[k], straight.stress_wall[k]) << "minimum " << k;
  for (std::size_t k = 2; k < lb.strain.size(); ++k) {
    EXPECT_LT(lb.max_force[k], o.force_tol * lb.force_scale) << "minimum " << k;
    EXPECT_LE(std::abs(lb.stress_wall[k] - lb.stress_virial[k]), lb.equilibrium_bound) << "minimum " << k;
  }
}

// A branch at another increment goes on from the parent's last minimum with
// its own increment: its strains continue from there, its minima meet the
// tolerance, and its own checkpoint resumes bit for bit (the branch point
// is part of the state).
TEST(QuasistaticResume, BranchAtAnotherIncrementContinuesFromTheParentsLastMinimum) {
  const LoadedScene scene = test::scene({"contact.youngs_modulus=\"2 GPa\""});
  QuasistaticOptions o = smoke_options();
  o.strain = 1e-3;
  o.force_tol = 1e-4;
  test::TempDir dir("aqs_branch_increment");
  const std::string parent_ckpt = (dir.path() / "parent.bin").string(), ckpt = (dir.path() / "branch.bin").string();
  QuasistaticRun parent = quasistatic_run(scene, o);
  while (!parent.done()) parent.step();  // minima at strain 0 and 1e-3
  {
    ArchiveWriter w(parent_ckpt);
    parent.save(w);
    w.close();
  }
  const QuasistaticResult p = parent.finish();
  QuasistaticOptions b = o;
  b.strain_increment = 5e-4;
  b.strain = 3e-3;
  const auto branch = [&] {
    QuasistaticRun run = quasistatic_run(scene, b);
    ArchiveReader in(parent_ckpt);
    run.load(in, true);
    in.expect_end();
    return run;
  };
  QuasistaticRun straight = branch();
  EXPECT_EQ(straight.next_increment(), 2u);
  EXPECT_EQ(straight.increments(), 5u);  // 1.5e-3, 2e-3, 2.5e-3, 3e-3 after the parent's two
  for (int k = 0; k < 2; ++k) straight.step();
  {
    ArchiveWriter w(ckpt);
    straight.save(w);
    w.close();
  }
  while (!straight.done()) straight.step();
  const QuasistaticResult r = straight.finish();
  const std::vector<double> strains{0.0, 1e-3, 1.5e-3, 2e-3, 2.5e-3, 3e-3};
  ASSERT_EQ(r.strain.size(), strains.size());
  for (std::size_t k = 0; k < strains.size(); ++k) EXPECT_NEAR(r.strain[k], strains[k], 1e-15) << "minimum " << k;
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(r.stress_wall[k], p.stress_wall[k]) << "minimum " << k;
  for (std::size_t k = 2; k < r.strain.size(); ++k) {
    EXPECT_LT(r.max_force[k], r.force_tol) << "minimum " << k;
    EXPECT_LE(std::abs(r.stress_wall[k] - r.stress_virial[k]), r.equilibrium_bound) << "minimum " << k;
  }
  QuasistaticRun resumed = quasistatic_run(scene, b);
  {
    ArchiveReader in(ckpt);
    resumed.load(in);
    in.expect_end();
  }
  EXPECT_EQ(resumed.increments(), 5u);
  while (!resumed.done()) resumed.step();
  const QuasistaticResult again = resumed.finish();
  ASSERT_EQ(again.strain.size(), r.strain.size());
  for (std::size_t k = 0; k < r.strain.size(); ++k) {
    EXPECT_EQ(again.strain[k], r.strain[k]) << "minimum " << k;
    EXPECT_EQ(again.stress_wall[k], r.stress_wall[k]) << "minimum " << k;
  }
}

// --start-from: the last frame of a frames.xyz replaces the built
// positions. Started from the frame of another run's last minimum, the
// first minimum is that minimum again (to the tolerance: its stress within
// the static-equilibrium bound, in a few evaluations instead of the
// thousands from the packing); the earlier frame in the file is ignored.
TEST(QuasistaticStart, FromTheLastFrameOfAFramesFile) {
  const LoadedScene scene = test::scene({"contact.youngs_modulus=\"2 GPa\""});
  QuasistaticOptions o = smoke_options();
  o.strain = 2e-3;
  o.force_tol = 1e-6;
  const QuasistaticResult parent = run_quasistatic(scene, o);
  test::TempDir dir("aqs_start");
  const std::string frames = (dir.path() / "frames.xyz").string();
  {
    std::ofstream out(frames);
    write_frame(out, build_shear_cell(scene.config), R, 0.0);  // an earlier frame: the packing
    write_frame(out, parent.final_cell, R, 1.5);
  }
  const Frame f = read_last_frame(frames, "--start-from");
  EXPECT_EQ(f.time, 1.5);
  ASSERT_EQ(f.free.size(), parent.final_cell.free.size());
  for (std::size_t i = 0; i < f.free.size(); ++i)
    ASSERT_EQ(f.free[i], parent.final_cell.free.x[i]) << "sphere " << i;  // exact: 17 digits
  QuasistaticOptions one = o;
  one.strain = 1e-3;
  QuasistaticRun run = quasistatic_run(scene, one, frames);
  const QuasistaticPoint first = run.step();
  EXPECT_NEAR(first.stress_wall, parent.stress_wall.back(), 2 * parent.equilibrium_bound);
  EXPECT_LT(first.iterations, parent.iterations[0] / 20) << "from the packing: " << parent.iterations[0];
  std::printf("  from the frame: %ld iterations (from the packing %ld); wall stress %.4f Pa against %.4f Pa\n",
              first.iterations, parent.iterations[0], first.stress_wall, parent.stress_wall.back());

  // A frame of another cell, and a file that is not a frames file.
  const std::string small = (dir.path() / "pair.xyz").string(), broken = (dir.path() / "broken.xyz").string();
  {
    ShearCell pair;
    pair.box = Box{100e-6, 40e-6, 40e-6};
    pair.free.x = {Vec3(0, 1e-5, 1e-5), Vec3(6e-6, 1e-5, 1e-5)};
    std::ofstream out(small);
    write_frame(out, pair, R, 0.0);
    std::ofstream bad(broken);
    bad << "2\nTime=0\nFe 0 0 0 2.5e-6\nNi 1 1 1 2.5e-6\n";
  }
  const auto message = [&](const std::string& path) {
    try {
      (void)quasistatic_run(scene, one, path);
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "--start-from");
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(small).find("2 free and 0 wall spheres"), std::string::npos) << message(small);
  EXPECT_NE(message(broken).find("line 4"), std::string::npos) << message(broken);
  EXPECT_NE(message(broken).find("'Ni'"), std::string::npos) << message(broken);
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
