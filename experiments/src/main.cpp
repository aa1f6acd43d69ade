// The `mrf` command line (DESIGN.md §Interfaces).
//   mrf run SCENE.toml [--set section.key=value]... [--out DIR] [--quiet]
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "mrf/error.hpp"
#include "mrf/scene/run.hpp"

namespace {

int run_command(const std::string& scene_path, const std::vector<std::string>& sets,
                std::string out, bool quiet) {
  const mrf::LoadedScene scene = mrf::load_scene(scene_path, sets);
  if (out.empty()) out = "out/" + std::filesystem::path(scene_path).stem().string();
  const mrf::RunSummary s = mrf::run_scene(scene, {out, quiet});
  std::printf("%s Mn=%.4g: stress_total = %.6g +- %.2g Pa (particles %.6g, fluid %.6g, virial %.6g +- %.2g), "
              "drift z = %.2f; %ld steps, %.1f s -> %s/summary.json\n",
              s.model.c_str(), s.mason, s.stress_total.mean, s.stress_total.err,
              s.stress_particles.mean, s.stress_fluid, s.stress_virial.mean, s.stress_virial.err,
              s.stress_total.drift_z, s.steps, s.wall_seconds, out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mrf: magnetorheological fluid in a shear cell (DEM, DEM-SPH)"};
  app.require_subcommand(1);
  auto* run = app.add_subcommand("run", "run one scene and write summary.json and timeseries.csv");
  std::string scene, out;
  std::vector<std::string> sets;
  bool quiet = false;
  run->add_option("scene", scene, "scene file (TOML)")->required();
  run->add_option("--set", sets, "override one key: section.key=value (repeatable)");
  run->add_option("--out", out, "output directory (default out/<scene name>)");
  run->add_flag("--quiet", quiet, "no start-up table or progress on stderr");
  CLI11_PARSE(app, argc, argv);
  try {
    if (*run) return run_command(scene, sets, out, quiet);
  } catch (const mrf::InputError& e) {
    std::fprintf(stderr, "mrf: error: %s\n", e.what());
    return 2;
  } catch (const mrf::NumericalError& e) {
    std::fprintf(stderr, "\nmrf: numerical failure: %s\n", e.what());
    return 3;
  }
  return 0;
}
