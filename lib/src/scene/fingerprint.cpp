// The scene fingerprint (every parameter of a scene, exactly: what a
// checkpoint resumes into and what a sweep archive's scene_id hashes), and
// what two fingerprints disagree on. Declared in scene/run_series.hpp.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "mrf/io/checksum.hpp"
#include "mrf/scene/run_series.hpp"

namespace mrf {

namespace {
// The scene keys a fingerprint holds, in its order (the order is part of
// every archived scene_id: append, never reorder).
constexpr const char* k_fingerprint_keys[] = {
    "box.gap", "box.ly", "box.lz", "particles.radius", "particles.volume_fraction", "particles.density",
    "particles.magnetization", "particles.dipole_cutoff", "walls.spacing", "contact.youngs_modulus",
    "contact.poisson_ratio", "fluid.viscosity", "fluid.density", "fluid.sph_spacing", "fluid.sound_speed",
    "drive.mason", "drive.shear_rate", "drive.strain", "drive.warmup_strain", "numerics.dt", "numerics.skin",
    "numerics.dt_safety", "numerics.implicit_tol", "scene.model", "numerics.integrator", "scene.seed",
    "numerics.threads", "numerics.implicit_order", "output.every", "output.frames"};
constexpr std::size_t k_fingerprint_fields = std::size(k_fingerprint_keys);
// Keys that came later: only a value other than the one every scene had
// before the key came enters, tagged, after the fields above, so that the
// scene_id of every earlier scene stays what it was (append, never reorder).
// That value is a literal here, not the default: fluid.eos_reference's
// default became "common" after the key came, and "start" still enters
// nothing.
struct LaterKey {
  const char* key;
  const char* tag;
  const char* shown_when_absent;
};
constexpr LaterKey k_later_keys[] = {{"numerics.newton_tol", "newton_tol ", "1e-06 (default)"},
                                     {"fluid.eos_reference", "eos_reference ", "start"}};

std::string hex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}
}  // namespace

std::string scene_fingerprint(const SceneConfig& c) {
  const std::string values[] = {
      hex(c.gap), hex(c.ly), hex(c.lz), hex(c.radius), hex(c.volume_fraction), hex(c.density), hex(c.magnetization),
      hex(c.dipole_cutoff), hex(c.wall_spacing), hex(c.youngs_modulus), hex(c.poisson_ratio), hex(c.viscosity),
      hex(c.fluid_density), hex(c.sph_spacing), hex(c.sound_speed), hex(c.mason), hex(c.shear_rate), hex(c.strain),
      hex(c.warmup_strain), hex(c.dt.value_or(-1.0)), hex(c.skin), hex(c.dt_safety), hex(c.implicit_tol),
      to_string(c.model), to_string(c.integrator), std::to_string(c.seed), std::to_string(c.threads),
      std::to_string(c.implicit_order), std::to_string(c.every), std::to_string(c.frames)};
  static_assert(std::size(values) == k_fingerprint_fields, "one key per fingerprint field");
  std::string out;
  for (const std::string& v : values) {
    if (!out.empty()) out += ';';
    out += v;
  }
  // the defaults when the keys came, literals, so that a new default cannot alias them
  if (c.newton_tol != 1e-6) out += std::string(";") + k_later_keys[0].tag + hex(c.newton_tol);
  // the carrier's EOS only where there is a carrier with spheres in it (a
  // two-way scene without spheres builds the fluid alone, whose particles
  // all have the fluid density as their reference either way)
  if (!is_one_way(c.model) && c.volume_fraction > 0 && c.eos_reference != EosReference::start)
    out += std::string(";") + k_later_keys[1].tag + to_string(c.eos_reference);
  return out;
}

namespace {
// the fields as written (numbers in hex), keyed by position
std::vector<std::pair<std::string, std::string>> fingerprint_fields(const std::string& fp) {
  std::vector<std::pair<std::string, std::string>> out;
  for (std::size_t start = 0, k = 0; start <= fp.size(); ++k) {
    const std::size_t end = std::min(fp.find(';', start), fp.size());
    std::string text = fp.substr(start, end - start);
    std::string key = k < k_fingerprint_fields ? k_fingerprint_keys[k] : "field " + std::to_string(k + 1);
    for (const LaterKey& later : k_later_keys)
      if (k >= k_fingerprint_fields && text.rfind(later.tag, 0) == 0)
        key = later.key, text.erase(0, std::strlen(later.tag));
    out.emplace_back(key, text);
    start = end + 1;
  }
  return out;
}

const LaterKey* later_key(const std::string& key) {
  for (const LaterKey& later : k_later_keys)
    if (key == later.key) return &later;
  return nullptr;
}

std::size_t base_fields(const std::vector<std::pair<std::string, std::string>>& f) {
  return static_cast<std::size_t>(
      std::count_if(f.begin(), f.end(), [](const auto& field) { return later_key(field.first) == nullptr; }));
}

std::string value_in(const std::vector<std::pair<std::string, std::string>>& f, const std::string& key) {
  for (const auto& [k, v] : f)
    if (k == key) return v;
  return std::string();  // a later key at its default
}
}  // namespace

std::vector<std::string> fingerprint_keys_differing(const std::string& was, const std::string& now) {
  const auto a = fingerprint_fields(was), b = fingerprint_fields(now);
  if (base_fields(a) != k_fingerprint_fields || base_fields(b) != k_fingerprint_fields) return {"(format)"};
  std::vector<std::string> out;
  std::vector<std::string> keys(std::begin(k_fingerprint_keys), std::end(k_fingerprint_keys));
  for (const LaterKey& later : k_later_keys) keys.emplace_back(later.key);
  for (const std::string& key : keys)
    if (value_in(a, key) != value_in(b, key)) out.push_back(key);
  return out;
}

std::string fingerprint_difference(const std::string& was, const std::string& now) {
  if (was == now) return "";
  const auto a = fingerprint_fields(was), b = fingerprint_fields(now);
  if (base_fields(a) != k_fingerprint_fields || base_fields(b) != k_fingerprint_fields)
    return "the checkpoint's scene fingerprint has " + std::to_string(base_fields(a)) +
           " fields where this version writes " + std::to_string(k_fingerprint_fields) +
           ": it comes from another version of mrf";
  // a value for display: a number in %.10g, or in %.17g where the two
  // values differ beyond ten digits; numerics.dt -1 is "auto"
  auto show = [](const std::string& key, const std::string& text, int digits) {
    if (text.rfind("0x", 0) != 0 && text.rfind("-0x", 0) != 0) return text;
    const double v = std::strtod(text.c_str(), nullptr);
    if (key == "numerics.dt" && v == -1.0) return std::string("auto");
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return std::string(buf);
  };
  std::string out;
  for (const std::string& key : fingerprint_keys_differing(was, now)) {
    const std::string va = value_in(a, key), vb = value_in(b, key);
    std::string sa = show(key, va, 10), sb = show(key, vb, 10);
    if (sa == sb) sa = show(key, va, 17), sb = show(key, vb, 17);
    if (const LaterKey* later = later_key(key)) {
      if (va.empty()) sa = later->shown_when_absent;
      if (vb.empty()) sb = later->shown_when_absent;
    }
    out += (out.empty() ? "" : "; ") + key + " " + sa + " in the checkpoint, " + sb + " now";
  }
  return out.empty() ? "the fingerprints differ in no named key" : out;
}

std::string fingerprint_id(const std::string& fingerprint) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08x", static_cast<unsigned>(crc32(fingerprint)));
  return buf;
}

std::string scene_id(const SceneConfig& c) { return fingerprint_id(scene_fingerprint(c)); }

}  // namespace mrf
