// `mrf run` on the fluid-only SPH scene: the same entry point and files as
// the DEM model, and a steady wall stress of eta*gdot (issue 4).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mrf/error.hpp"
#include "mrf/scene/run.hpp"

namespace mrf {
namespace {

TEST(RunFluidOnly, CouetteSceneWritesSummaryWithEtaGdot) {
  const LoadedScene scene = load_scene(MRF_SOURCE_DIR "/experiments/scenes/couette_sph.toml");
  const std::string out = (std::filesystem::temp_directory_path() / "mrf_run_fluid").string();
  std::filesystem::remove_all(out);
  const RunSummary s = run_scene(scene, {out, true});
  const double eta_gdot = scene.config.viscosity * scene.config.shear_rate;
  EXPECT_NEAR(s.stress_total.mean, eta_gdot, 0.01 * eta_gdot);
  EXPECT_EQ(s.stress_particles.mean, 0.0);
  EXPECT_GT(s.n_fluid, 0);
  std::ifstream in(out + "/summary.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* key : {"model", "mason", "shear_rate", "stress_total", "stress_fluid", "n_fluid", "dt",
                          "steps", "reynolds_number", "profile_error_l2", "version"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["model"], "demsph_stokes");
  EXPECT_LT(j["profile_error_l2"].get<double>(), 1e-3);
  EXPECT_TRUE(std::filesystem::exists(out + "/timeseries.csv"));
}

// With particles the coupled model runs (verification/coupling/); an SPH
// spacing that does not tile the box is refused naming key and file line.
TEST(RunFluidOnly, CoupledSceneWithBadSphSpacingNamesKeyAndLine) {
  const LoadedScene scene = load_scene(MRF_SOURCE_DIR "/experiments/scenes/couette_sph.toml",
                                       {"particles.volume_fraction=0.1", "box.ly=45e-6"});
  try {
    run_scene(scene, {"", true});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fluid.sph_spacing"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("couette_sph.toml:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mrf
