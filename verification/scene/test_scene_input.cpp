// Scene files (io/toml_scene): a valid scene parses to SI values, units convert,
// the Mason number follows Mn = 9 eta gdot / (2 mu0 M^2) (DESIGN.md), overrides
// replace values and are validated, and every class of bad input is an
// InputError that names the key, the value as written and its line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mrf/error.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/vec.hpp"

namespace mrf {
namespace {

// The paper scene (DESIGN.md), with units spelled in several ways.
const std::string k_scene = R"(# a comment
[scene]
model = "dem_stokes"
seed = 7

[box]
gap = "150 um"
ly = 50e-6
lz = "0.12 mm"

[particles]
radius = "2.5 um"
volume_fraction = 0.3
density = "7.87 g/cm^3"
magnetization = "1 MA/m"
dipole_cutoff = "20 um"

[walls]
spacing = "2.5 um"

[contact]
youngs_modulus = "200 GPa"
poisson_ratio = 0.3

[fluid]
viscosity = "0.1 Pa s"
density = 1000

[drive]
mason = 0.01
strain = 5
warmup_strain = 1

[numerics]
integrator = "verlet_exp"
dt = "2 ns"
skin = "0.5 um"

[output]
every = 100
frames = 10
)";

// 1-based number of the first line of `text` that starts with `start`.
int line_of(const std::string& text, const std::string& start) {
  std::size_t pos = 0;
  for (int n = 1; pos < text.size(); ++n) {
    if (text.compare(pos, start.size(), start) == 0) return n;
    pos = text.find('\n', pos) + 1;
    if (pos == 0) break;
  }
  ADD_FAILURE() << "no line starting with " << start;
  return -1;
}

// `text` with the line starting with `start` replaced by `with` ("" deletes it).
std::string edit(const std::string& text, const std::string& start, const std::string& with) {
  const std::size_t b = text.find("\n" + start) + 1;
  const std::size_t e = text.find('\n', b) + 1;
  return text.substr(0, b) + (with.empty() ? "" : with + "\n") + text.substr(e);
}

std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, "scene.toml", overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(SceneInput, ValidSceneParsesToSi) {
  const LoadedScene s = parse_scene(k_scene, "scene.toml");
  const SceneConfig& c = s.config;
  EXPECT_EQ(c.model, ModelId::dem_stokes);
  EXPECT_EQ(c.seed, 7u);
  EXPECT_DOUBLE_EQ(c.gap, 150e-6);
  EXPECT_DOUBLE_EQ(c.ly, 50e-6);
  EXPECT_DOUBLE_EQ(c.lz, 120e-6);
  EXPECT_DOUBLE_EQ(c.radius, 2.5e-6);
  EXPECT_DOUBLE_EQ(c.volume_fraction, 0.3);
  EXPECT_DOUBLE_EQ(c.density, 7870);
  EXPECT_DOUBLE_EQ(c.magnetization, 1e6);
  EXPECT_DOUBLE_EQ(c.dipole_cutoff, 20e-6);
  EXPECT_DOUBLE_EQ(c.wall_spacing, 2.5e-6);
  EXPECT_DOUBLE_EQ(c.youngs_modulus, 200e9);
  EXPECT_DOUBLE_EQ(c.poisson_ratio, 0.3);
  EXPECT_DOUBLE_EQ(c.viscosity, 0.1);
  EXPECT_DOUBLE_EQ(c.fluid_density, 1000);
  EXPECT_DOUBLE_EQ(c.mason, 0.01);
  EXPECT_DOUBLE_EQ(c.strain, 5);
  EXPECT_DOUBLE_EQ(c.warmup_strain, 1);
  EXPECT_EQ(c.integrator, IntegratorId::verlet_exp);
  ASSERT_TRUE(c.dt.has_value());
  EXPECT_DOUBLE_EQ(*c.dt, 2e-9);
  EXPECT_DOUBLE_EQ(c.skin, 0.5e-6);
  EXPECT_EQ(c.every, 100);
  EXPECT_EQ(c.frames, 10);
  EXPECT_EQ(s.where.at("particles.radius"), "scene.toml:12");  // counted by hand
  EXPECT_EQ(s.locate("numerics.dt"), "scene.toml:" + std::to_string(line_of(k_scene, "dt =")));
  EXPECT_EQ(s.locate("numerics.threads"), "scene.toml");  // a default
}

TEST(SceneInput, MasonAndShearRateFollowTheClosedForm) {
  const double eta = 0.1, m = 1e6;
  const SceneConfig c = parse_scene(k_scene, "scene.toml").config;
  EXPECT_DOUBLE_EQ(9 * eta * c.shear_rate / (2 * k_mu0 * m * m), 0.01);
  const std::string by_rate = edit(k_scene, "mason =", "shear_rate = \"30 1/s\"");
  const SceneConfig r = parse_scene(by_rate, "s").config;
  EXPECT_DOUBLE_EQ(r.shear_rate, 30);
  EXPECT_DOUBLE_EQ(r.mason, 9 * eta * 30 / (2 * k_mu0 * m * m));
}

// M = 0 with drive.shear_rate: non-magnetic particles (and the fluid-only
// scenes, volume_fraction = 0) are valid; the Mason number is infinite.
TEST(SceneInput, ZeroMagnetizationWithShearRateGivesAnInfiniteMasonNumber) {
  const std::string text = edit(edit(k_scene, "mason =", "shear_rate = \"100 1/s\""), "magnetization =",
                                "magnetization = 0");
  for (const char* phi : {"0.3", "0.0"}) {
    const LoadedScene s = parse_scene(text, "scene.toml", {std::string("particles.volume_fraction=") + phi});
    EXPECT_EQ(s.config.shear_rate, 100) << phi;
    EXPECT_TRUE(std::isinf(s.config.mason) && s.config.mason > 0) << phi << ": Mn = " << s.config.mason;
  }
}

// drive.vary = "magnetization": the Mason number at a fixed shear rate,
// M = sqrt(9 eta gdot / (2 mu0 Mn)) replacing the file's magnetisation
// (REFERENCE §8); the shear rate is needed, and the default still takes
// drive.mason at the given M.
TEST(SceneInput, MagnetizationFollowsTheMasonNumberAtAFixedShearRate) {
  const double eta = 0.1;
  for (const double mn : {1e-3, 3e-2, 1.0}) {
    const LoadedScene s = parse_scene(k_scene, "scene.toml",
                                      {"drive.vary=\"magnetization\"", "drive.shear_rate=1e3",
                                       "drive.mason=" + std::to_string(mn)});
    EXPECT_EQ(s.config.vary, MasonBy::magnetization);
    EXPECT_DOUBLE_EQ(s.config.shear_rate, 1e3);
    EXPECT_DOUBLE_EQ(s.config.mason, mn);
    EXPECT_NEAR(s.config.magnetization, std::sqrt(9 * eta * 1e3 / (2 * k_mu0 * mn)), 1e-9 * s.config.magnetization);
    EXPECT_NEAR(9 * eta * s.config.shear_rate / (2 * k_mu0 * std::pow(s.config.magnetization, 2)), mn, 1e-12 * mn);
  }
  EXPECT_NEAR(parse_scene(k_scene, "s", {"drive.vary=\"magnetization\"", "drive.shear_rate=1e3", "drive.mason=1e-3"})
                  .config.magnetization,
              6.0e5, 0.01 * 6.0e5);  // REFERENCE §8: Mn = 1e-3 at 1e3 1/s is M = 6.0e5 A/m
  try {
    parse_scene(k_scene, "s", {"drive.vary=\"magnetization\""});  // the file gives drive.mason only
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "drive.shear_rate") << e.what();
  }
  EXPECT_EQ(parse_scene(k_scene, "s").config.vary, MasonBy::shear_rate);
}

TEST(SceneInput, OptionalKeysTakeTheirDefaults) {
  const std::string text = edit(edit(k_scene.substr(0, k_scene.find("[numerics]")), "model =",
                                     "model = \"demsph_dd\""),
                                "density = 1000", "density = 1000\nsph_spacing = 1e-6");
  const SceneConfig c = parse_scene(text, "s").config;
  EXPECT_EQ(c.model, ModelId::demsph_dd);
  EXPECT_DOUBLE_EQ(c.sph_spacing, 1e-6);
  EXPECT_EQ(c.integrator, IntegratorId::automatic);
  EXPECT_FALSE(c.dt.has_value());
  EXPECT_EQ(c.skin, 0.0);
  EXPECT_EQ(c.dt_safety, 0.5);
  EXPECT_EQ(c.implicit_tol, 1e-2);
  EXPECT_EQ(c.implicit_order, 2);
  EXPECT_EQ(c.newton_tol, 1e-6);
  EXPECT_EQ(c.sound_speed, 0.0);
  EXPECT_EQ(c.threads, 1);
  EXPECT_EQ(c.every, 0);
  EXPECT_EQ(c.frames, 0);
}

TEST(SceneInput, EveryUnitConvertsToSi) {
  struct Case {
    const char* set;
    double SceneConfig::*field;
    double si;
  };
  const Case cases[] = {
      {"box.gap=0.15", &SceneConfig::gap, 0.15},  // plain numbers are SI
      {"box.gap=\"1 m\"", &SceneConfig::gap, 1},
      {"box.gap=\"0.2 mm\"", &SceneConfig::gap, 0.2e-3},
      {"particles.radius=\"2500 nm\"", &SceneConfig::radius, 2.5e-6},
      {"particles.radius=\"2.5 \u00b5m\"", &SceneConfig::radius, 2.5e-6},
      {"particles.radius=2.5um", &SceneConfig::radius, 2.5e-6},  // unquoted: taken as a string
      {"contact.youngs_modulus=\"5 Pa\"", &SceneConfig::youngs_modulus, 5},
      {"contact.youngs_modulus=\"5 kPa\"", &SceneConfig::youngs_modulus, 5e3},
      {"contact.youngs_modulus=\"5 MPa\"", &SceneConfig::youngs_modulus, 5e6},
      {"contact.youngs_modulus=7", &SceneConfig::youngs_modulus, 7},  // an integer
      {"fluid.viscosity=\"0.2 Pa*s\"", &SceneConfig::viscosity, 0.2},
      {"fluid.viscosity=\"20 mPa s\"", &SceneConfig::viscosity, 20e-3},
      {"fluid.viscosity=\"20 mPa*s\"", &SceneConfig::viscosity, 20e-3},
      {"fluid.density=\"960 kg/m^3\"", &SceneConfig::fluid_density, 960},
      {"fluid.density=\"960 kg/m3\"", &SceneConfig::fluid_density, 960},
      {"fluid.density=\"0.96 g/cm3\"", &SceneConfig::fluid_density, 960},
      {"particles.magnetization=\"500 A/m\"", &SceneConfig::magnetization, 500},
      {"particles.magnetization=\"500 kA/m\"", &SceneConfig::magnetization, 5e5},
      {"fluid.sound_speed=\"3 m/s\"", &SceneConfig::sound_speed, 3},
      {"drive.shear_rate=\"4 s^-1\"", &SceneConfig::shear_rate, 4},
      {"drive.shear_rate=\"4 1/s\"", &SceneConfig::shear_rate, 4},
  };
  for (const Case& k : cases)
    EXPECT_DOUBLE_EQ(parse_scene(k_scene, "s", {k.set}).config.*k.field, k.si) << k.set;
  for (const char* dt : {"\"1 s\"", "\"1000 ms\"", "\"1e6 us\"", "\"1e9 ns\"", "1.0"})
    EXPECT_DOUBLE_EQ(*parse_scene(k_scene, "s", {std::string("numerics.dt=") + dt}).config.dt, 1)
        << dt;
  EXPECT_FALSE(parse_scene(k_scene, "s", {"numerics.dt=auto"}).config.dt.has_value());
}

TEST(SceneInput, OverridesReplaceValuesAndRecordWhere) {
  const LoadedScene s =
      parse_scene(k_scene, "s", {"drive.mason=0.1", "numerics.integrator=overdamped"});
  EXPECT_DOUBLE_EQ(s.config.mason, 0.1);
  EXPECT_DOUBLE_EQ(s.config.shear_rate, shear_rate_from_mason(0.1, 0.1, 1e6));
  EXPECT_EQ(s.config.integrator, IntegratorId::overdamped);
  EXPECT_EQ(s.locate("drive.mason"), "--set drive.mason=0.1");
  // An override of shear_rate replaces the file's mason instead of clashing with it.
  const SceneConfig r = parse_scene(k_scene, "s", {"drive.shear_rate=2"}).config;
  EXPECT_DOUBLE_EQ(r.shear_rate, 2);
  EXPECT_DOUBLE_EQ(r.mason, mason_from_shear_rate(2, 0.1, 1e6));
}

TEST(SceneInput, BadOverridesNameTheSetOption) {
  const std::string bad = error_of(k_scene, {"particles.radius=-1"});
  EXPECT_EQ(bad.rfind("--set particles.radius=-1: key 'particles.radius' = -1: must be > 0", 0), 0u)
      << bad;
  const std::string unknown = error_of(k_scene, {"particles.radiu=1"});
  EXPECT_EQ(unknown, "--set particles.radiu=1: key 'particles.radiu' = 1: unknown key "
                     "(did you mean 'particles.radius'?)");
  const std::string both = error_of(k_scene, {"drive.mason=1", "drive.shear_rate=1"});
  EXPECT_PRED_FORMAT2(testing::IsSubstring, "only one of drive.mason", both);
  const std::string no_eq = error_of(k_scene, {"drive.mason"});
  EXPECT_PRED_FORMAT2(testing::IsSubstring, "--set drive.mason", no_eq);
  // found by test_fuzz_scene: an empty key, and a NUL that cut the message short
  EXPECT_EQ(error_of(k_scene, {"=0"}), "key '--set' = =0: expected section.key=value: the key before '=' is empty");
  EXPECT_EQ(error_of(k_scene, {""}).rfind("--set : key '--set': expected section.key=value", 0), 0u);
  const std::string nul = error_of(k_scene, {std::string("drive.strai\0=1", 14)});
  EXPECT_PRED_FORMAT2(testing::IsSubstring, "drive.strai\\x00", nul);
}

// Found by test_fuzz_scene: an extreme viscosity overflowed the shear rate
// derived from Mn to inf (or flushed it to 0), and the scene was accepted.
TEST(SceneInput, DerivedDriveOutOfRangeIsRefusedNamingTheMasonNumber) {
  for (const char* eta : {"fluid.viscosity=1e-320", "fluid.viscosity=1e308"}) {
    const std::string e = error_of(k_scene, {eta});
    EXPECT_PRED_FORMAT2(testing::IsSubstring, "key 'drive.mason'", e);
    EXPECT_PRED_FORMAT2(testing::IsSubstring, "gives shear rate (1/s) =", e);
  }
}

TEST(SceneInput, LoadsAFileAndNamesAMissingOne) {
  const std::string path = testing::TempDir() + "mrf_scene_input.toml";
  std::ofstream(path) << edit(k_scene, "radius =", "radius = -1");
  const std::string msg = [&] {
    try {
      load_scene(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  }();
  EXPECT_EQ(msg.rfind(path + ":12: key 'particles.radius' = -1: must be > 0", 0), 0u) << msg;
  EXPECT_DOUBLE_EQ(load_scene(path, {"particles.radius=\"3 um\""}).config.radius, 3e-6);
  std::filesystem::remove(path);
  try {
    load_scene(path);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_PRED_FORMAT2(testing::IsSubstring, path, e.what());
    EXPECT_PRED_FORMAT2(testing::IsSubstring, "no such file", e.what());
  }
}

// ---- bad input: one case per class -----------------------------------------

struct Bad {
  const char* name;
  const char* line;   // start of the line of k_scene to replace
  const char* with;   // its replacement; "" deletes it
  const char* key;    // expected in the message ...
  const char* value;  // ... with the value as written ("" for none) ...
  const char* why;    // ... and this reason
};

class SceneBadInput : public testing::TestWithParam<Bad> {};

TEST_P(SceneBadInput, NamesKeyValueAndLine) {
  const Bad& b = GetParam();
  const std::string msg = error_of(edit(k_scene, b.line, b.with));
  const int line = std::string(b.with).empty() ? 0 : line_of(k_scene, b.line);
  const std::string where = line > 0 ? "scene.toml:" + std::to_string(line) : "scene.toml";
  const std::string value = *b.value ? std::string(" = ") + b.value : "";
  EXPECT_EQ(msg.rfind(where + ": key '" + b.key + "'" + value + ": ", 0), 0u) << msg;
  EXPECT_PRED_FORMAT2(testing::IsSubstring, b.why, msg);
}

const Bad k_bad[] = {
    {"UnknownKey", "radius =", "radiuss = 1", "particles.radiuss", "1",
     "unknown key (did you mean 'particles.radius'?)"},
    {"KeyInWrongSection", "spacing =", "radius = 1", "walls.radius", "1",
     "did you mean 'particles.radius'?"},
    {"UnknownSection", "[walls]", "[wals]", "wals", "", "unknown key: there is no section [wals]"},
    {"MissingKey", "gap =", "", "box.gap", "", "missing key"},
    {"NegativeRadius", "radius =", "radius = -2.5e-6", "particles.radius", "-2.5e-06",
     "must be > 0"},
    {"ZeroRadius", "radius =", "radius = \"0 um\"", "particles.radius", "\"0 um\"", "must be > 0"},
    {"NanRadius", "radius =", "radius = nan", "particles.radius", "nan", "not a finite number"},
    {"Unpackable", "volume_fraction =", "volume_fraction = 0.34", "particles.volume_fraction",
     "0.34", "cannot be packed: effective fraction"},
    {"WrongUnit", "radius =", "radius = \"2 GPa\"", "particles.radius", "\"2 GPa\"",
     "wrong unit 'GPa' for a length (expected m, mm, um, nm)"},
    {"UnknownUnit", "lz =", "lz = \"1 ft\"", "box.lz", "\"1 ft\"", "unknown unit 'ft'"},
    {"MissingUnit", "radius =", "radius = \"2.5\"", "particles.radius", "\"2.5\"",
     "missing unit for a length"},
    {"UnitOnDimensionless", "volume_fraction =", "volume_fraction = \"0.3 um\"",
     "particles.volume_fraction", "\"0.3 um\"", "takes no unit"},
    {"MasonAndShearRate", "mason =", "mason = 0.01\nshear_rate = 10", "drive.mason", "0.01",
     "only one of drive.mason and drive.shear_rate"},
    {"NoMasonNorShearRate", "mason =", "", "drive.mason", "", "missing key"},
    {"ZeroMagnetizationWithMason", "magnetization =", "magnetization = 0", "particles.magnetization", "0",
     "must be > 0 when drive.mason is given"},
    {"WarmupNotBelowStrain", "warmup_strain =", "warmup_strain = 5.0", "drive.warmup_strain",
     "5", "must be < drive.strain"},
    {"BadIntegrator", "integrator =", "integrator = \"rk4\"", "numerics.integrator", "\"rk4\"",
     "expected one of: auto, verlet_exp, overdamped, implicit"},
    {"ImplicitTolAboveOne", "skin =", "implicit_tol = 2", "numerics.implicit_tol", "2", "must be in (0, 1]"},
    {"ImplicitOrderThree", "skin =", "implicit_order = 3", "numerics.implicit_order", "3", "must be 1 or 2"},
    {"NewtonTolAboveOnePercent", "skin =", "newton_tol = 0.1", "numerics.newton_tol", "0.1", "must be in (0, 0.01]"},
    {"BadModel", "model =", "model = \"dem\"", "scene.model", "\"dem\"",
     "expected one of: dem_stokes, demsph_stokes, demsph_dd"},
    {"CutoffBeyondMinimumImage", "dipole_cutoff =", "dipole_cutoff = \"25 um\"",
     "particles.dipole_cutoff", "\"25 um\"", "(minimum image)"},
    {"CutoffBelowContact", "dipole_cutoff =", "dipole_cutoff = \"4 um\"",
     "particles.dipole_cutoff", "\"4 um\"", "must be >= 2*radius"},
    {"SeedNotInteger", "seed =", "seed = 1.5", "scene.seed", "1.5", "expected an integer"},
    {"BadEosReference", "density = 1000", "eos_reference = \"first\"\ndensity = 1000", "fluid.eos_reference",
     "\"first\"", "expected one of: start, common"},
    {"SyntaxError", "radius =", "radius = 2.5 um", "particles.radius", "2.5 um",
     "TOML syntax error"},
};

INSTANTIATE_TEST_SUITE_P(Scene, SceneBadInput, testing::ValuesIn(k_bad),
                         [](const testing::TestParamInfo<Bad>& i) { return i.param.name; });

}  // namespace
}  // namespace mrf
