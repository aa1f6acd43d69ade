// Claims on sweep points (study/point_claim.hpp): several `mrf sweep`
// processes on one output, and a refused checkpoint that must not fail its
// point. The two processes racing on one sweep are ctest SweepClaims
// (sweep_claim_check.py).
#include "mrf/study/point_claim.hpp"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "mrf/study/sweep.hpp"

namespace mrf {
namespace {

const std::string k_scenes = MRF_SOURCE_DIR "/experiments/scenes";

std::filesystem::path fresh(const char* name) {
  const auto d = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(d);
  return d;
}

TEST(PointClaim, OneHolderAtATimeWithinAProcess) {
  const auto dir = fresh("mrf_test_claim_one") / "dem_stokes/mn_1_seed_1";
  EXPECT_EQ(point_claim_holder(dir), "");  // no claim file: nobody, and nothing created
  EXPECT_FALSE(std::filesystem::exists(dir));
  {
    const PointClaim first(dir);
    ASSERT_TRUE(first.owned());
    const PointClaim second(dir);  // another open file: the lock conflicts even within one process
    EXPECT_FALSE(second.owned());
    const std::string me = "pid " + std::to_string(getpid()) + " on host ";
    EXPECT_EQ(second.holder().rfind(me, 0), 0u) << second.holder();
    EXPECT_EQ(point_claim_holder(dir).rfind(me, 0), 0u);
  }
  EXPECT_EQ(point_claim_holder(dir), "");  // released with its owner
  const PointClaim again(dir);
  EXPECT_TRUE(again.owned());
}

// A claim held by another process, and dropped by the kernel when that
// process is killed (no stale claim after a SIGKILL).
// `--list` probes a claim with a shared lock for a moment: a sweep that
// tries to claim the point just then waits it out instead of leaving the
// point to whoever held it last.
TEST(PointClaim, AMomentaryProbeDoesNotKeepTheClaim) {
  const auto dir = fresh("mrf_test_claim_probe") / "point";
  { const PointClaim first(dir); }  // the file exists, as after an earlier run
  const int probe = ::open(point_claim_path(dir).c_str(), O_RDONLY);
  ASSERT_GE(probe, 0);
  ASSERT_EQ(::flock(probe, LOCK_SH | LOCK_NB), 0);
  std::thread release([probe] {
    ::usleep(50000);
    ::close(probe);
  });
  const PointClaim claim(dir);
  release.join();
  EXPECT_TRUE(claim.owned());
}

TEST(PointClaim, HeldByAnotherProcessUntilItIsKilled) {
  const auto dir = fresh("mrf_test_claim_child") / "p";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const PointClaim c(dir);
    const char ok = c.owned() ? 'y' : 'n';
    if (write(ready[1], &ok, 1) != 1) _exit(1);
    for (;;) pause();
  }
  char ok = 0;
  ASSERT_EQ(read(ready[0], &ok, 1), 1);
  ASSERT_EQ(ok, 'y');
  {
    const PointClaim mine(dir);
    EXPECT_FALSE(mine.owned());
    EXPECT_EQ(mine.holder().rfind("pid " + std::to_string(child) + " on host ", 0), 0u) << mine.holder();
  }
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(ready[0]);
  close(ready[1]);
  EXPECT_EQ(point_claim_holder(dir), "");
  const PointClaim mine(dir);
  EXPECT_TRUE(mine.owned());
}

SweepSpec two_points() {
  return parse_sweep(
      "[sweep]\nscene = \"small_dem_stokes.toml\"\nmodels = [\"dem_stokes\"]\nmason = [0.3, 1.0]\nseeds = [4]\n"
      "set = [\"drive.strain=0.2\", \"drive.warmup_strain=0.05\", \"numerics.threads=1\"]\n",
      "tiny.toml", k_scenes);
}

// A point whose claim another process holds is left to it: not run, not
// failed, not counted as finished.
TEST(PointClaim, SweepLeavesAClaimedPointToItsHolder) {
  const auto out = fresh("mrf_test_claim_sweep");
  const SweepSpec s = two_points();
  const auto pts = sweep_points(s);
  SweepOptions opt;
  opt.quiet = true;
  const PointClaim held(out / pts[0].dir);
  ASSERT_TRUE(held.owned());
  const SweepOutcome o = run_sweep(s, out.string(), opt);
  EXPECT_EQ(o.ran, 1u);
  EXPECT_EQ(o.elsewhere, 1u);
  EXPECT_EQ(o.failed, 0u);
  EXPECT_FALSE(point_finished((out / pts[0].dir).string()));
  EXPECT_TRUE(std::filesystem::exists(out / pts[1].dir / "summary.json"));
}

// A run of another scene in a claimed point's folder (the process running
// it had other rules) is not set aside from under its holder: the folder
// stays where the running process writes it. Once the claim is gone, the
// next sweep sets it aside and runs the point.
TEST(PointClaim, StaleFolderOfAClaimedPointStaysPut) {
  const auto out = fresh("mrf_test_claim_stale");
  const SweepSpec s = two_points();
  const auto pts = sweep_points(s);
  const auto dir = out / pts[0].dir;
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"scene_id": "0123abcd", "stress_total": 1.0})";
  SweepOptions opt;
  opt.quiet = true;
  {
    const PointClaim held(dir);
    ASSERT_TRUE(held.owned());
    const SweepOutcome o = run_sweep(s, out.string(), opt);
    EXPECT_EQ(o.elsewhere, 1u);
    EXPECT_EQ(o.ran, 1u);
    EXPECT_TRUE(std::filesystem::exists(dir / "summary.json"));
    EXPECT_FALSE(std::filesystem::exists(dir.string() + ".stale-0123abcd"));
    EXPECT_TRUE(point_stale(s, pts[0], dir));
  }
  const SweepOutcome o = run_sweep(s, out.string(), opt);
  EXPECT_EQ(o.ran, 1u);
  EXPECT_TRUE(std::filesystem::exists(dir.string() + ".stale-0123abcd/summary.json"));
  EXPECT_TRUE(point_finished(dir.string()));
  EXPECT_FALSE(point_stale(s, pts[0], dir));
}

// A checkpoint of another format version (a build before or after this one
// wrote it) is refused, and the point keeps it: no failure.json, which would
// mark the point done and, to run it again, cost the folder and the run's
// progress with it. The sweep goes on with the other point.
TEST(PointClaim, SweepLeavesAPointWithARefusedCheckpointAsItIs) {
  const auto out = fresh("mrf_test_claim_refused");
  const SweepSpec s = two_points();
  const auto pts = sweep_points(s);
  const auto dir = out / pts[0].dir;
  std::filesystem::create_directories(dir);
  std::string old(64, '\0');
  old.replace(0, 8, std::string("MRFCKPT\0", 8));
  const std::uint32_t marker = 0x01020304u, version = 1;  // the headerless format's number: never this build's
  old.replace(8, 4, reinterpret_cast<const char*>(&marker), 4);
  old.replace(12, 4, reinterpret_cast<const char*>(&version), 4);
  std::ofstream(dir / "checkpoint.bin", std::ios::binary) << old;
  std::ofstream(dir / "timeseries.csv") << "strain\n";
  SweepOptions opt;
  opt.quiet = true;
  const SweepOutcome o = run_sweep(s, out.string(), opt);
  EXPECT_EQ(o.refused, 1u);
  EXPECT_EQ(o.failed, 0u);
  EXPECT_EQ(o.ran, 1u);
  EXPECT_FALSE(point_finished(dir.string()));
  std::ifstream in(dir / "checkpoint.bin", std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), old);
  EXPECT_TRUE(std::filesystem::exists(out / pts[1].dir / "summary.json"));
}

}  // namespace
}  // namespace mrf
