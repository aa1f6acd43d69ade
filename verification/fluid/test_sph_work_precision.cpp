// Work-precision driver (Slow, writes reports/sph/work_precision.csv; plot
// with reports/sph/plot_work_precision.py). Start-up Couette, gdot = 100/s,
// oil (sph_channel.hpp): relative L2 profile error at t = 0.05 L^2/nu
// (start-up) and 0.25 L^2/nu (near steady) against wall time, for the
// explicit solver at half its viscous limit and implicit viscosity at 0.5,
// 2 and 7.5 times the viscous limit (7.5x = half the CFL limit), at 10, 15,
// 20, 30 and 60 particles across the gap.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "sph_channel.hpp"

namespace mrf::test {
namespace {

struct Row {
  std::string scheme;
  int n;
  double dt_factor, dt, wall_startup, err_startup, wall_steady, err_steady;
  std::int64_t steps;
};

Row measure(int n, bool implicit, double dt_factor) {
  FluidCell c = channel(n, 100.0, 0.0);
  Row r{implicit ? "implicit" : "explicit", n, dt_factor, 0, 0, 0, 0, 0, 0};
  r.dt = dt_factor * 0.125 * c.h * c.h / k_nu;
  const auto t0 = std::chrono::steady_clock::now();
  run_to(c, 0.05 * k_t_visc, r.dt, implicit);
  r.wall_startup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.err_startup = profile_error(c, couette_exact(c, c.time));
  run_to(c, 0.25 * k_t_visc, r.dt, implicit);
  r.wall_steady = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.err_steady = profile_error(c, couette_exact(c, c.time));
  r.steps = c.steps;
  return r;
}

TEST(SphWorkPrecisionSlow, WriteCsv) {
  const std::string path = std::string(MRF_SOURCE_DIR) + "/reports/sph/work_precision.csv";
  std::ofstream out(path);
  ASSERT_TRUE(out) << path;
  out << "# start-up Couette, gap 150 um, eta 0.1 Pa s, rho 1000 kg/m^3, gdot 100/s, h/dx 1.3, 1 thread\n"
      << "scheme,n_across,dt_over_viscous_limit,dt_s,steps_to_steady,wall_s_startup,err_startup,"
         "wall_s_steady,err_steady\n";
  for (int n : {10, 15, 20, 30, 60}) {
    std::vector<Row> rows{measure(n, false, 0.5)};
    for (double f : {0.5, 2.0, 7.5}) rows.push_back(measure(n, true, f));
    for (const Row& r : rows) {
      out << r.scheme << ',' << r.n << ',' << r.dt_factor << ',' << r.dt << ',' << r.steps << ','
          << r.wall_startup << ',' << r.err_startup << ',' << r.wall_steady << ',' << r.err_steady << '\n';
      EXPECT_LT(r.err_startup, 0.1) << r.scheme << " n " << n << " dt x" << r.dt_factor;
    }
  }
}

}  // namespace
}  // namespace mrf::test
