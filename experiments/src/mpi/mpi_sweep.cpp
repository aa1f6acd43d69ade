// `mpirun -n K mrf sweep FILE`: rank 0 hands the points out one at a time,
// the most expensive estimate first (estimates calibrated by the points
// already finished, mrf::estimate_points), to ranks 1..K-1 as they ask.
// A worker runs each point in a child process (`mrf sweep FILE --point J`,
// resuming from the point's checkpoint) and reports how it ended: finished,
// failed numerically (failure.json), or died (a signal such as the OOM
// killer's SIGKILL, or an abnormal exit): a point that died keeps its
// checkpoint, is reported, and the sweep goes on; the next sweep resumes it.
// Rank 0 waits without spinning (it shares the cores with the workers) and
// writes the one complete sweep.csv at the end. A point's result does not
// depend on which rank ran it or when (bit for bit: test).
#include <mpi.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "mrf/study/sweep.hpp"

extern char** environ;

namespace {
enum Tag { k_ready = 1, k_work = 2, k_done = 3 };
enum Ended : long { k_finished = 0, k_failed = 1, k_died = 2 };

// Runs `command` + {"--point", J} as a child process; how it ended, and a
// description when it died.
Ended run_point(const std::vector<std::string>& command, long job, std::string& why) {
  std::vector<std::string> args = command;
  args.push_back("--point");
  args.push_back(std::to_string(job));
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int e = posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ); e != 0) {
    why = std::string("could not start: ") + std::strerror(e);
    return k_died;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) {
      why = std::string("waitpid: ") + std::strerror(errno);
      return k_died;
    }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return k_finished;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 4) return k_failed;  // failure.json written
  why = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                                  strsignal(WTERMSIG(status)) + ")"
                            : "exit status " + std::to_string(WEXITSTATUS(status));
  return k_died;
}

// A blocking receive that sleeps instead of polling the shared-memory
// transport: rank 0 would otherwise take a core from the workers.
void receive_sleeping(long* msg, int n, MPI_Status* st) {
  MPI_Request req;
  MPI_Irecv(msg, n, MPI_LONG, MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &req);
  int done = 0;
  for (;;) {
    MPI_Test(&req, &done, st);
    if (done) return;
    const timespec pause{0, 20'000'000};  // 20 ms: nothing next to a point's seconds
    nanosleep(&pause, nullptr);
  }
}

}  // namespace

int mpi_sweep(const mrf::SweepSpec& spec, const std::string& out, const mrf::SweepOptions& opt,
              const std::vector<std::string>& point_command) {
  MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const auto points = mrf::sweep_points(spec);
  int status = 0;
  if (rank == 0) {
    mrf::set_aside_stale(spec, points, out, opt.quiet);
    if (!opt.archive.empty())
      mrf::report_archive(mrf::restore_from_archive(spec, points, out, opt.archive), opt.archive, opt.quiet);
    const mrf::PointEstimates est = mrf::estimate_points(spec, points, out, opt.cost_rate, opt.archive, opt.calibrate);
    // what is left of each point to run: a run under way only the rest of its
    // strain; a folder of another scene still here belongs to a running process
    std::vector<long> order;
    std::vector<double> left(points.size(), 0.0);
    for (const auto& p : points) {
      if (mrf::point_finished(spec, p, out)) continue;
      order.push_back(static_cast<long>(p.index));
      left[p.index] = est.seconds[p.index] * mrf::point_fraction_left(spec, p, out);
    }
    const auto key = [&](long k) { return std::isfinite(left[k]) ? left[k] : -1.0; };
    std::stable_sort(order.begin(), order.end(), [&](long a, long b) { return key(a) > key(b); });
    if (!opt.quiet)
      std::fprintf(stderr, "mrf sweep (MPI): %zu points, %zu to run on %d workers, the most expensive first\n",
                   points.size(), order.size(), size - 1);
    std::size_t next = 0;
    int active = size - 1;
    long failed = 0, ran = 0;
    std::vector<std::string> died;
    while (active > 0) {
      long msg[2];
      MPI_Status st;
      receive_sleeping(msg, 2, &st);
      if (st.MPI_TAG == k_done) {
        const std::string& dir = points[static_cast<std::size_t>(msg[0])].dir;
        if (msg[1] == k_finished) ++ran;
        if (msg[1] == k_failed) ++failed;
        if (msg[1] == k_died) died.push_back(dir);
        if (!opt.quiet || msg[1] == k_died)
          std::fprintf(stderr, "mrf sweep (MPI): rank %d %s %s\n", st.MPI_SOURCE,
                       msg[1] == k_died ? "lost the run of" : "finished", dir.c_str());
      }
      long job = next < order.size() ? order[next++] : -1;
      MPI_Send(&job, 1, MPI_LONG, st.MPI_SOURCE, k_work, MPI_COMM_WORLD);
      if (job < 0) --active;
    }
    mrf::write_sweep_csv(points, out, &spec);
    std::printf("sweep (MPI, %d ranks): %ld run, %zu skipped (finished before), %ld failed, %zu died -> %s/sweep.csv\n",
                size, ran, points.size() - order.size(), failed, died.size(), out.c_str());
    for (const std::string& d : died)
      std::printf("  %s did not finish (its run died); it is resumable: run the sweep again\n", d.c_str());
    status = failed || !died.empty() ? 4 : 0;
  } else {
    long msg[2] = {-1, 0};
    MPI_Send(msg, 2, MPI_LONG, 0, k_ready, MPI_COMM_WORLD);
    for (;;) {
      long job = -1;
      MPI_Recv(&job, 1, MPI_LONG, 0, k_work, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (job < 0) break;
      std::string why;
      const Ended ended = run_point(point_command, job, why);
      if (ended == k_died)
        std::fprintf(stderr, "mrf sweep (MPI): rank %d, point %ld (%s): %s\n", rank, job,
                     points[static_cast<std::size_t>(job)].dir.c_str(), why.c_str());
      msg[0] = job;
      msg[1] = ended;
      MPI_Send(msg, 2, MPI_LONG, 0, k_done, MPI_COMM_WORLD);
    }
  }
  MPI_Finalize();
  return status;
}
