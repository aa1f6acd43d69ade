// Checkpoints of the quasi-static driver (quasistatic/aqs.hpp): a restored
// run continues bit for bit and extends; a checkpoint of other options is
// refused by name; a branch may change the tolerance, the minimiser or the
// increment and goes on from the parent's last minimum; --start-from
// relaxes the first minimum from the last frame of a frames file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "mrf/error.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/quasistatic/aqs.hpp"
#include "mrf/scene/run_series.hpp"
#include "smoke_options.hpp"
#include "support/files.hpp"
#include "support/small_scene.hpp"

namespace mrf {
namespace {

using test::smoke_options;

constexpr double R = 2.5e-6;

void save(const QuasistaticRun& run, const std::string& path) {
  ArchiveWriter w(path);
  run.save(w);
  w.close();
}

void load(QuasistaticRun& run, const std::string& path, bool branch = false) {
  ArchiveReader in(path);
  run.load(in, branch);
  in.expect_end();
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
  save(first, ckpt);
  while (!first.done()) first.step();
  const QuasistaticResult straight = first.finish();
  QuasistaticRun resumed = quasistatic_run(scene, o);
  load(resumed, ckpt);
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
  load(extended, ckpt);
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
  save(parent, ckpt);
  while (!parent.done()) parent.step();
  const QuasistaticResult straight = parent.finish();
  auto branch = [&](double tol) {
    QuasistaticOptions b = o;
    b.force_tol = tol;
    QuasistaticRun run = quasistatic_run(scene, b);
    load(run, ckpt, true);
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
  load(run, ckpt, true);
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
  save(parent, parent_ckpt);
  const QuasistaticResult p = parent.finish();
  QuasistaticOptions b = o;
  b.strain_increment = 5e-4;
  b.strain = 3e-3;
  const auto branch = [&] {
    QuasistaticRun run = quasistatic_run(scene, b);
    load(run, parent_ckpt, true);
    return run;
  };
  QuasistaticOptions too_short = b;
  too_short.strain = 1e-3;  // the parent's own end: nothing left to branch
  QuasistaticRun refused = quasistatic_run(scene, too_short);
  EXPECT_THROW(load(refused, parent_ckpt, true), NumericalError);
  QuasistaticRun straight = branch();
  EXPECT_EQ(straight.next_increment(), 2u);
  EXPECT_EQ(straight.increments(), 5u);  // 1.5e-3, 2e-3, 2.5e-3, 3e-3 after the parent's two
  for (int k = 0; k < 2; ++k) straight.step();
  save(straight, ckpt);
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
  load(resumed, ckpt);
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

}  // namespace
}  // namespace mrf
