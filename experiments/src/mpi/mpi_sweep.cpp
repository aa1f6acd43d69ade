// `mpirun -n K mrf sweep FILE`: rank 0 hands the points out one at a time,
// the most expensive estimate first (estimates calibrated by the points
// already finished, mrf::estimate_points), to ranks 1..K-1 as they ask;
// each worker runs its point (resuming from its checkpoint) and reports
// it; rank 0 writes the one complete sweep.csv at the end. A point's result
// does not depend on which rank ran it or when (bit for bit: test).
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "mrf/io/atomic_file.hpp"
#include "mrf/study/sweep.hpp"

namespace {
enum Tag { k_ready = 1, k_work = 2, k_done = 3 };
}

int mpi_sweep(const mrf::SweepSpec& spec, const std::string& out, const mrf::SweepOptions& opt) {
  MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const auto points = mrf::sweep_points(spec);
  int status = 0;
  if (rank == 0) {
    const mrf::PointEstimates est = mrf::estimate_points(spec, points, out, opt.cost_rate);
    std::vector<long> order;
    for (const auto& p : points)
      if (!mrf::point_finished((std::filesystem::path(out) / p.dir).string())) order.push_back(static_cast<long>(p.index));
    const auto key = [&](long k) { return std::isfinite(est.seconds[k]) ? est.seconds[k] : -1.0; };
    std::stable_sort(order.begin(), order.end(), [&](long a, long b) { return key(a) > key(b); });
    if (!opt.quiet)
      std::fprintf(stderr, "mrf sweep (MPI): %zu points, %zu to run on %d workers, the most expensive first\n",
                   points.size(), order.size(), size - 1);
    std::size_t next = 0;
    int active = size - 1;
    long failed = 0, ran = 0;
    while (active > 0) {
      long msg[2];
      MPI_Status st;
      MPI_Recv(msg, 2, MPI_LONG, MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
      if (st.MPI_TAG == k_done) {
        ++ran;
        failed += msg[1] != 0 ? 1 : 0;
        if (!opt.quiet)
          std::fprintf(stderr, "mrf sweep (MPI): rank %d finished %s%s\n", st.MPI_SOURCE,
                       points[static_cast<std::size_t>(msg[0])].dir.c_str(), msg[1] ? " (failed)" : "");
      }
      long job = next < order.size() ? order[next++] : -1;
      MPI_Send(&job, 1, MPI_LONG, st.MPI_SOURCE, k_work, MPI_COMM_WORLD);
      if (job < 0) --active;
    }
    std::filesystem::create_directories(out);
    mrf::write_file_atomic((std::filesystem::path(out) / "sweep.csv").string(), mrf::sweep_csv(points, out));
    std::printf("sweep (MPI, %d ranks): %ld run, %zu skipped (finished before), %ld failed -> %s/sweep.csv\n", size, ran,
                points.size() - order.size(), failed, out.c_str());
    status = failed ? 4 : 0;
  } else {
    long msg[2] = {-1, 0};
    MPI_Send(msg, 2, MPI_LONG, 0, k_ready, MPI_COMM_WORLD);
    for (;;) {
      long job = -1;
      MPI_Recv(&job, 1, MPI_LONG, 0, k_work, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (job < 0) break;
      mrf::SweepOptions o = opt;
      o.point = job;
      o.quiet = true;
      o.write_csv = false;  // rank 0 writes the one sweep.csv
      long failed = 0;
      try {
        failed = static_cast<long>(mrf::run_sweep(spec, out, o).failed);
      } catch (const std::exception& e) {  // a full disk, say: the point stays resumable
        std::fprintf(stderr, "mrf sweep (MPI): rank %d, point %ld: %s\n", rank, job, e.what());
        failed = 1;
      }
      msg[0] = job;
      msg[1] = failed;
      MPI_Send(msg, 2, MPI_LONG, 0, k_done, MPI_COMM_WORLD);
    }
  }
  MPI_Finalize();
  return status;
}
