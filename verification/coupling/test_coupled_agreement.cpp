// The inertialess coupled scheme against the inertial one where the particle
// Stokes number is small (small scene, Mn = 1e-2, St = 3e-3, model 3, six
// seeds, strain 3 with 1 of warm-up): the wall stress and the volume-side
// stress agree within 2 combined standard errors (seed scatter of the paired
// differences with the within-run errors). scripts/coupled-agreement runs the
// full comparison (models 2 and 3, Mn = 1e-2 and 0.1) into
// reports/inertia/coupled_agreement.md. Label slow: the inertial runs take
// about 15 s each.
//
// Six seeds, as the issue asked, since session 42: with three the seed
// scatter has two degrees of freedom and the verdict turned on one run's
// within-run error. Over seeds 1-3 the Jacobian's C_J (session 42) gave
// +604 +- 234 Pa (2.6 errors, failed) where the code before gave +598 +- 353
// (1.7, passed): the same offset, a smaller error bar on seed 2. Over seeds
// 1-12 both give +1.4 % (1.0 combined errors; docs/performance.md).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

RunSummary run(const char* integrator, int seed) {
  const LoadedScene scene =
      load_scene(MRF_SOURCE_DIR "/experiments/scenes/small_demsph_dd.toml",
                 {std::string("numerics.integrator=\"") + integrator + "\"", "scene.seed=" + std::to_string(seed),
                  "drive.mason=1e-2", "drive.strain=3", "drive.warmup_strain=1"});
  return run_scene(scene, {"", true});
}

TEST(SlowCoupledAgreement, InertialessEqualsInertialAtSmallStokesNumber) {
  std::vector<double> dw, dv;
  double within_w = 0, within_v = 0, cost_inertial = 0, cost_inertialess = 0;
  for (int seed : {1, 2, 3, 4, 5, 6}) {
    const RunSummary a = run("verlet_exp", seed), b = run("implicit", seed);
    ASSERT_EQ(b.integrator.rfind("inertialess", 0), 0u) << b.integrator;
    dw.push_back(b.stress_total.mean - a.stress_total.mean);
    dv.push_back(b.extra.at("stress_virial_total") - a.extra.at("stress_virial_total"));
    within_w += a.stress_total.err * a.stress_total.err + b.stress_total.err * b.stress_total.err;
    within_v += std::pow(a.extra.at("stress_virial_total_err"), 2) + std::pow(b.extra.at("stress_virial_total_err"), 2);
    cost_inertial += a.wall_seconds;
    cost_inertialess += b.wall_seconds;
  }
  auto check = [](const std::vector<double>& d, double within, const char* what) {
    const double n = static_cast<double>(d.size());
    double mean = 0, var = 0;
    for (double x : d) mean += x / n;
    for (double x : d) var += (x - mean) * (x - mean) / (n - 1);
    const double err = std::hypot(std::sqrt(var / n), std::sqrt(within) / n);
    EXPECT_LT(std::abs(mean), 2.0 * err) << what << ": difference " << mean << " +- " << err << " Pa";
    return mean / err;
  };
  RecordProperty("wall_difference_in_errors", std::to_string(check(dw, within_w, "wall stress")));
  RecordProperty("volume_difference_in_errors", std::to_string(check(dv, within_v, "volume stress")));
  RecordProperty("cost_ratio_inertial_over_inertialess", std::to_string(cost_inertial / cost_inertialess));
}

}  // namespace
}  // namespace mrf
