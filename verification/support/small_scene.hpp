// The small scene of experiments/scenes/small_dem_stokes.toml as scene text
// for the run tests (verification/scene/test_run.cpp, test_time_step.cpp):
// a short drive, one thread, a time-series row every 25 steps; and the
// small helpers that edit it and read numbers back.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/io/toml_scene.hpp"

namespace mrf::test {

inline const std::string k_source = "small.toml";

// experiments/scenes/small_dem_stokes.toml with a short drive, one thread and
// a time-series row every 25 steps.
inline const std::string k_scene = R"([scene]
model = "dem_stokes"
seed = 1

[box]
gap = "80 um"
ly = "32 um"
lz = "32 um"

[particles]
radius = "2.5 um"
volume_fraction = 0.30
density = "7800 kg/m^3"
magnetization = "1000 kA/m"
dipole_cutoff = "15 um"

[walls]
spacing = "2.5 um"

[contact]
youngs_modulus = "200 GPa"
poisson_ratio = 0.3

[fluid]
viscosity = "0.1 Pa s"
density = "1000 kg/m^3"

[drive]
mason = 1e-2
strain = 0.3
warmup_strain = 0.1

[numerics]
integrator = "verlet_exp"
dt = "auto"
threads = 1

[output]
every = 25
)";
inline constexpr double k_eta = 0.1, k_m = 1e6, k_strain = 0.3, k_warmup = 0.1;
inline constexpr int k_every = 25;

inline LoadedScene scene(const std::vector<std::string>& overrides = {}, const std::string& text = k_scene) {
  return parse_scene(text, k_source, overrides);
}

// 1-based number of the line of `text` that starts with `start`.
inline int line_of(const std::string& text, const std::string& start) {
  std::istringstream in(text);
  std::string l;
  for (int n = 1; std::getline(in, l); ++n)
    if (l.starts_with(start)) return n;
  ADD_FAILURE() << "no line starting with " << start;
  return -1;
}

inline std::string with_dt(const std::string& value) {
  std::string text = k_scene;
  const std::string from = "dt = \"auto\"";
  text.replace(text.find(from), from.size(), "dt = " + value);
  return text;
}

inline std::string g17(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

inline double rel(double a, double b) { return std::abs(a - b) / std::max(std::abs(a), std::abs(b)); }

}  // namespace mrf::test
