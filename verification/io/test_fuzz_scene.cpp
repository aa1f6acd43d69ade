// Fuzzing the scene parser (parse_scene and its --set overrides) with an
// in-tree mutation loop: the committed scenes and sweep-style overrides are
// the seed corpus, mutated byte- and token-wise (flips, insertions,
// deletions, line swaps and duplications, splices between files, extreme
// numbers, wrong types, truncation). Every input must either parse to a
// finite, positive configuration or be refused with an InputError that
// names a key; anything else (another exception, a non-finite accepted
// value) fails the test and is written to verification/io/fuzz_regressions/
// (inputs kept there are replayed first, every run; a .set file holds the
// overrides, one per line in hex). MRF_FUZZ_RUNS sets the
// number of mutated inputs (default 1e5, a few seconds); MRF_FUZZ_SEED the seed.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/toml_scene.hpp"

namespace mrf {
namespace {

namespace fs = std::filesystem;
const fs::path k_root = MRF_SOURCE_DIR;
const fs::path k_regressions = k_root / "verification/io/fuzz_regressions";

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> corpus() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(k_root / "experiments/scenes"))
    if (e.path().extension() == ".toml") out.push_back(read_text(e.path()));
  std::sort(out.begin(), out.end());  // directory order is not fixed
  return out;
}

std::vector<std::string> lines_of(const std::string& t) {
  std::vector<std::string> v;
  std::stringstream s(t);
  for (std::string l; std::getline(s, l);) v.push_back(l);
  return v;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& l : v) s += l + "\n";
  return s;
}

const char* const k_values[] = {"0", "-1", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "\"nan m\"",
                                "\"\"", "\"2.5\"", "\"2.5 parsec\"", "\"1e3 um\"", "true", "[1, 2]", "{a = 1}",
                                "2147483648", "-2147483649", "9223372036854775807", "0.5", "\"auto\"", "\"-3 um\"",
                                "1979-05-27", "\"implicit\"", "\"magnetization\"", "1e-30", "3"};
const char* const k_keys[] = {"scene.model", "scene.seed", "box.gap", "box.ly", "box.lz", "particles.radius",
                              "particles.volume_fraction", "particles.magnetization", "particles.dipole_cutoff",
                              "walls.spacing", "contact.youngs_modulus", "contact.poisson_ratio",
                              "fluid.viscosity", "fluid.sph_spacing", "drive.mason", "drive.shear_rate",
                              "drive.vary", "drive.strain", "drive.warmup_strain", "numerics.dt",
                              "numerics.integrator", "numerics.threads", "numerics.implicit_order",
                              "output.every", "output.frames", "nosuch.key", "drive", "=", ""};

struct Mutator {
  std::mt19937_64 rng;
  const std::vector<std::string>& seeds;
  std::size_t pick(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); }
  template <class T, std::size_t N>
  const T& any(const T (&a)[N]) { return a[pick(N)]; }

  std::string text() {
    std::string t = seeds[pick(seeds.size())];
    const int rounds = 1 + static_cast<int>(pick(4));
    for (int r = 0; r < rounds; ++r) t = once(t);
    return t;
  }
  std::string once(const std::string& t) {
    std::vector<std::string> l = lines_of(t);
    switch (pick(9)) {
      case 0: {  // flip a byte
        std::string s = t;
        if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1 + pick(255));
        return s;
      }
      case 1: {  // insert a random byte or a TOML punctuation character
        std::string s = t;
        static const char punct[] = "=\"[]{}#.,\\\n 0e-+'";
        const char c = pick(2) ? punct[pick(sizeof punct - 1)] : static_cast<char>(pick(256));
        s.insert(s.begin() + static_cast<long>(pick(s.size() + 1)), c);
        return s;
      }
      case 2: {  // delete a range
        std::string s = t;
        if (s.empty()) return s;
        const std::size_t a = pick(s.size());
        s.erase(a, 1 + pick(std::min<std::size_t>(40, s.size() - a)));
        return s;
      }
      case 3:  // truncate
        return t.substr(0, t.empty() ? 0 : pick(t.size()));
      case 4:  // swap two lines (a key can leave its section)
        if (l.size() > 1) std::swap(l[pick(l.size())], l[pick(l.size())]);
        return join(l);
      case 5:  // duplicate a line (a key given twice)
        if (!l.empty()) l.insert(l.begin() + static_cast<long>(pick(l.size())), l[pick(l.size())]);
        return join(l);
      case 6: {  // splice: a line from another scene
        const auto other = lines_of(seeds[pick(seeds.size())]);
        if (!other.empty()) l.insert(l.begin() + static_cast<long>(pick(l.size() + 1)), other[pick(other.size())]);
        return join(l);
      }
      case 7: {  // replace the value of a key = value line
        if (l.empty()) return t;
        std::string& line = l[pick(l.size())];
        const auto eq = line.find('=');
        if (eq != std::string::npos) line = line.substr(0, eq + 1) + " " + any(k_values);
        return join(l);
      }
      default:  // drop a line (a required key missing)
        if (!l.empty()) l.erase(l.begin() + static_cast<long>(pick(l.size())));
        return join(l);
    }
  }
  std::vector<std::string> overrides() {
    std::vector<std::string> o;
    const std::size_t n = pick(3);
    for (std::size_t k = 0; k < n; ++k) {
      std::string s = std::string(any(k_keys)) + (pick(8) ? "=" : "") + any(k_values);
      if (pick(6) == 0) s = once(s);
      o.push_back(s);
    }
    return o;
  }
};

// "" if the outcome is acceptable, else what is wrong
std::string check(const std::string& text, const std::vector<std::string>& overrides) {
  try {
    const LoadedScene s = parse_scene(text, "fuzz.toml", overrides);
    const SceneConfig& c = s.config;
    for (double v : {c.gap, c.ly, c.lz, c.radius, c.shear_rate, c.strain, c.viscosity})
      if (!(std::isfinite(v) && v > 0)) return "accepted a non-finite or non-positive geometry/drive value";
    for (double v : {c.magnetization, c.volume_fraction, c.warmup_strain, c.youngs_modulus})
      if (!std::isfinite(v)) return "accepted a non-finite value";
    // Mn is infinite by design when M = 0 (no magnetic forces)
    if (!(c.mason > 0) || (!std::isfinite(c.mason) && c.magnetization > 0)) return "accepted a Mason number <= 0 or inf";
    if (c.dt && !(std::isfinite(*c.dt) && *c.dt > 0)) return "accepted a non-finite dt";
    return "";
  } catch (const InputError& e) {
    const std::string w = e.what();
    // a key, or for a TOML syntax error the line it is on
    const bool names_key = !e.key().empty() && w.find("key '") != std::string::npos;
    const bool names_line = w.rfind("fuzz.toml:", 0) == 0 && std::isdigit(static_cast<unsigned char>(w[10]));
    if (!names_key && !names_line) return "InputError naming neither a key nor a line: " + w;
    return "";
  } catch (const std::exception& e) {
    return std::string("not an InputError: ") + e.what();
  } catch (...) {
    return "a non-standard exception";
  }
}

// overrides, one per line in hex (they may hold any byte, newlines too)
std::string to_hex(const std::string& t) {
  static const char hex[] = "0123456789abcdef";
  std::string s;
  for (const char ch : t) {
    const auto u = static_cast<unsigned char>(ch);
    s += hex[u >> 4];
    s += hex[u & 15];
  }
  return s;
}
std::string from_hex(const std::string& h) {
  std::string s;
  for (std::size_t k = 0; k + 1 < h.size(); k += 2) s += static_cast<char>(std::stoi(h.substr(k, 2), nullptr, 16));
  return s;
}

void keep(const std::string& text, const std::vector<std::string>& overrides, const std::string& why) {
  fs::create_directories(k_regressions);
  const auto h = std::hash<std::string>{}(text + "\x1f" + [&] {
    std::string o;
    for (const auto& x : overrides) o += x + "\n";
    return o;
  }());
  std::ofstream(k_regressions / ("case_" + std::to_string(h) + ".toml")) << text;
  std::ofstream out(k_regressions / ("case_" + std::to_string(h) + ".set"));
  for (const auto& x : overrides) out << to_hex(x) << "\n";
  ADD_FAILURE() << why << "\n--- input ---\n" << text << "\n--- overrides ---\n" << [&] {
    std::string o;
    for (const auto& x : overrides) o += x + "\n";
    return o;
  }();
}

TEST(FuzzScene, KeptRegressionInputsAreHandled) {
  if (!fs::exists(k_regressions)) GTEST_SKIP() << "no regression inputs kept";
  int n = 0;
  for (const auto& e : fs::directory_iterator(k_regressions)) {
    if (e.path().extension() != ".toml") continue;
    std::vector<std::string> o;
    const fs::path set = fs::path(e.path()).replace_extension(".set");
    if (fs::exists(set))
      for (const auto& l : lines_of(read_text(set))) o.push_back(from_hex(l));
    EXPECT_EQ(check(read_text(e.path()), o), "") << e.path();
    ++n;
  }
  RecordProperty("inputs", n);
}

TEST(FuzzScene, MutatedScenesAndOverridesParseOrAreRefusedNamingAKey) {
  const auto seeds = corpus();
  ASSERT_GE(seeds.size(), 5u);
  const char* env_runs = std::getenv("MRF_FUZZ_RUNS");
  const char* env_seed = std::getenv("MRF_FUZZ_SEED");
  const long runs = env_runs ? std::atol(env_runs) : 100000;
  Mutator m{std::mt19937_64(env_seed ? std::strtoull(env_seed, nullptr, 10) : 20261201), seeds};
  long accepted = 0, refused = 0, failures = 0;
  double slowest = 0;
  for (long k = 0; k < runs && failures < 5; ++k) {
    const std::string text = m.text();
    const std::vector<std::string> o = m.pick(3) ? m.overrides() : std::vector<std::string>{};
    const auto t0 = std::chrono::steady_clock::now();
    const std::string why = check(text, o);
    slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!why.empty()) {
      ++failures;
      keep(text, o, why);
    } else {
      // count what the parser did (a second parse is cheap next to the test's budget)
      try {
        parse_scene(text, "fuzz.toml", o);
        ++accepted;
      } catch (const InputError&) {
        ++refused;
      }
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_LT(slowest, 1.0) << "an input took " << slowest << " s to parse";
  EXPECT_GT(accepted, runs / 100) << "the mutations should leave some scenes valid";
  RecordProperty("runs", std::to_string(runs));
  RecordProperty("accepted", std::to_string(accepted));
  RecordProperty("refused", std::to_string(refused));
  RecordProperty("slowest_s", std::to_string(slowest));
  std::printf("fuzz: %ld inputs, %ld accepted, %ld refused with a key, slowest %.3g s\n", runs, accepted, refused,
              slowest);
}

}  // namespace
}  // namespace mrf
