// Scene file loader. One table of key specs (k_keys) drives reading, defaults
// and missing-key checks; one table of rules (k_rules) drives validation.
// Quantities (numbers with units, ranges) are read by io/quantity.
#include "mrf/io/toml_scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/io/toml_text.hpp"

namespace mrf {
namespace {

// ---- values as written ---------------------------------------------------

using Value = WrittenValue;

Value value_of(const toml::node& n, std::string where) {
  Value out{std::monostate{}, "", std::move(where)};
  if (const auto* i = n.as_integer()) {
    out.v = i->get();
    out.text = std::to_string(i->get());
  } else if (const auto* d = n.as_floating_point()) {
    out.v = d->get();
    out.text = format_number(d->get());
  } else if (const auto* b = n.as_boolean()) {
    out.v = b->get();
    out.text = b->get() ? "true" : "false";
  } else if (const auto* s = n.as_string()) {
    out.v = s->get();
    out.text = "\"" + s->get() + "\"";
  } else if (!n.is_table()) {
    std::ostringstream os;
    os << toml::toml_formatter{n};
    out.text = os.str();
  }
  return out;
}

template <class E, std::size_t N>
E read_choice(const Value& val, const E (&all)[N]) {
  if (const auto* s = std::get_if<std::string>(&val.v))
    for (E e : all)
      if (*s == to_string(e)) return e;
  std::string list;
  for (E e : all) list += (list.empty() ? "" : ", ") + std::string(to_string(e));
  throw ValueError("expected one of: " + list);
}

// ---- the key table -------------------------------------------------------

enum class Need { required, optional, sph_models, one_of_drive };

using Target = std::variant<double SceneConfig::*, int SceneConfig::*, std::uint64_t SceneConfig::*,
                            ModelId SceneConfig::*, IntegratorId SceneConfig::*, MasonBy SceneConfig::*,
                            EosReference SceneConfig::*,
                            std::optional<double> SceneConfig::*>;

struct KeySpec {
  std::string_view key;  // "section.name"
  Target target;
  Dim dim;
  Need need;
  Range range;  // numbers only; integers are >= 0
};

using C = SceneConfig;
const KeySpec k_keys[] = {
    {"scene.model", &C::model, Dim::none, Need::required, k_any},
    {"scene.seed", &C::seed, Dim::none, Need::required, k_any},
    {"box.gap", &C::gap, Dim::length, Need::required, k_pos},
    {"box.ly", &C::ly, Dim::length, Need::required, k_pos},
    {"box.lz", &C::lz, Dim::length, Need::required, k_pos},
    {"particles.radius", &C::radius, Dim::length, Need::required, k_pos},
    {"particles.volume_fraction", &C::volume_fraction, Dim::none, Need::required,
     {0, 1, false, true}},
    {"particles.density", &C::density, Dim::density, Need::required, k_pos},
    {"particles.magnetization", &C::magnetization, Dim::magnetization, Need::required, k_nonneg},
    {"particles.dipole_cutoff", &C::dipole_cutoff, Dim::length, Need::required, k_pos},
    {"walls.spacing", &C::wall_spacing, Dim::length, Need::required, k_pos},
    {"contact.youngs_modulus", &C::youngs_modulus, Dim::pressure, Need::required, k_pos},
    {"contact.poisson_ratio", &C::poisson_ratio, Dim::none, Need::required, {-1, 0.5, true, true}},
    {"fluid.viscosity", &C::viscosity, Dim::viscosity, Need::required, k_pos},
    {"fluid.density", &C::fluid_density, Dim::density, Need::required, k_pos},
    {"fluid.sph_spacing", &C::sph_spacing, Dim::length, Need::sph_models, k_pos},
    {"fluid.sound_speed", &C::sound_speed, Dim::velocity, Need::optional, k_nonneg},
    {"fluid.eos_reference", &C::eos_reference, Dim::none, Need::optional, k_any},
    {"drive.vary", &C::vary, Dim::none, Need::optional, k_any},
    {"drive.mason", &C::mason, Dim::none, Need::one_of_drive, k_pos},
    {"drive.shear_rate", &C::shear_rate, Dim::rate, Need::one_of_drive, k_pos},
    {"drive.strain", &C::strain, Dim::none, Need::required, k_pos},
    {"drive.warmup_strain", &C::warmup_strain, Dim::none, Need::required, k_nonneg},
    {"numerics.integrator", &C::integrator, Dim::none, Need::optional, k_any},
    {"numerics.dt", &C::dt, Dim::time, Need::optional, k_pos},
    {"numerics.skin", &C::skin, Dim::length, Need::optional, k_nonneg},
    {"numerics.dt_safety", &C::dt_safety, Dim::none, Need::optional, {0, 1, true, false}},
    {"numerics.implicit_tol", &C::implicit_tol, Dim::none, Need::optional, {0, 1, true, false}},
    {"numerics.implicit_order", &C::implicit_order, Dim::none, Need::optional, k_any},
    {"numerics.newton_tol", &C::newton_tol, Dim::none, Need::optional, {0, 1e-2, true, false}},
    {"numerics.threads", &C::threads, Dim::none, Need::optional, k_any},
    {"output.every", &C::every, Dim::none, Need::optional, k_any},
    {"output.frames", &C::frames, Dim::none, Need::optional, k_any},
};

constexpr ModelId k_models[] = {ModelId::dem_stokes, ModelId::demsph_stokes, ModelId::demsph_dd, ModelId::dem_dd};
constexpr MasonBy k_vary[] = {MasonBy::shear_rate, MasonBy::magnetization};
constexpr EosReference k_eos_references[] = {EosReference::start, EosReference::common};
constexpr IntegratorId k_integrators[] = {IntegratorId::automatic, IntegratorId::verlet_exp,
                                          IntegratorId::overdamped, IntegratorId::implicit};

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};

void assign(SceneConfig& c, const KeySpec& spec, const Value& val) {
  std::visit(Overloaded{
                 [&](double C::*m) { c.*m = read_number(val, spec.dim, spec.range); },
                 [&](int C::*m) { c.*m = read_count<int>(val); },
                 [&](std::uint64_t C::*m) { c.*m = read_count<std::uint64_t>(val); },
                 [&](ModelId C::*m) { c.*m = read_choice(val, k_models); },
                 [&](IntegratorId C::*m) { c.*m = read_choice(val, k_integrators); },
                 [&](MasonBy C::*m) { c.*m = read_choice(val, k_vary); },
                 [&](EosReference C::*m) { c.*m = read_choice(val, k_eos_references); },
                 [&](std::optional<double> C::*m) {  // "auto" or a number
                   const auto* s = std::get_if<std::string>(&val.v);
                   if (s && trim(*s) == "auto") c.*m = std::nullopt;
                   else c.*m = read_number(val, spec.dim, spec.range);
                 },
             },
             spec.target);
}

const KeySpec* find_spec(std::string_view key) {
  for (const KeySpec& s : k_keys)
    if (s.key == key) return &s;
  return nullptr;
}

std::string_view section_of(std::string_view key) { return key.substr(0, key.find('.')); }
std::string_view name_of(std::string_view key) {
  const auto dot = key.find('.');
  return dot == std::string_view::npos ? key : key.substr(dot + 1);
}
bool is_section(std::string_view name) {
  return std::any_of(std::begin(k_keys), std::end(k_keys),
                     [&](const KeySpec& s) { return section_of(s.key) == name; });
}

// ---- unknown keys: suggestions -------------------------------------------

// The same name in another section, else the closest key (or section) within distance 2.
std::string suggestion(std::string_view wrong, bool want_section) {
  std::string best;
  std::size_t best_d = 3;
  for (const KeySpec& s : k_keys) {
    const std::string_view cand = want_section ? section_of(s.key) : s.key;
    if (!want_section && name_of(s.key) == name_of(wrong)) return std::string(cand);
    const std::size_t d = edit_distance(wrong, cand);
    if (d < best_d) {
      best = cand;
      best_d = d;
    }
  }
  return best;
}

std::string unknown_why(const std::string& key, bool is_table, bool at_root) {
  if (at_root && is_section(key)) return "expected one section [" + key + "]";
  const bool section = at_root && is_table;
  std::string why = section ? "unknown key: there is no section [" + key + "]" : "unknown key";
  const std::string hint = suggestion(key, section);
  if (!hint.empty()) why += " (did you mean '" + hint + "'?)";
  return why;
}

// ---- reading the document ------------------------------------------------

using Given = std::map<std::string, Value>;

struct Found {
  std::string key;
  Value value;
  std::uint32_t line;
  std::string error;  // empty for a known key
};

std::uint32_t line_of(const toml::key& k, const toml::node& n) {
  return k.source().begin.line > 0 ? k.source().begin.line : n.source().begin.line;
}

// Every key of the document, in file order; unknown ones carry their error.
std::vector<Found> flatten(const toml::table& doc, const std::string& source) {
  std::vector<Found> out;
  auto add = [&](std::string key, const toml::key& k, const toml::node& n, std::string error) {
    const std::uint32_t line = line_of(k, n);
    out.push_back({std::move(key), value_of(n, source + ":" + std::to_string(line)), line,
                   std::move(error)});
  };
  for (auto&& [sk, sn] : doc) {
    const std::string section(sk.str());
    const toml::table* table = sn.as_table();
    if (!table || !is_section(section)) {
      add(section, sk, sn, unknown_why(section, table != nullptr, true));
      continue;
    }
    for (auto&& [k, n] : *table) {
      std::string key = section + "." + std::string(k.str());
      std::string error = find_spec(key) ? "" : unknown_why(key, n.is_table(), false);
      add(std::move(key), k, n, std::move(error));
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Found& a, const Found& b) { return a.line < b.line; });
  return out;
}

toml::table parse_toml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    const std::uint32_t line = e.source().begin.line;
    const auto [key, value] = toml_key_on_line(text, line);
    throw InputError(key, value, source + ":" + std::to_string(line),
                     "TOML syntax error: " + std::string(e.description()));
  }
}

Given read_document(std::string_view text, const std::string& source) {
  Given given;
  for (Found& f : flatten(parse_toml(text, source), source)) {
    if (!f.error.empty()) throw InputError(f.key, f.value.text, f.value.where, f.error);
    given[f.key] = std::move(f.value);
  }
  return given;
}

// Override value: TOML syntax, or else the raw text as a string.
Value override_value(const std::string& raw, const std::string& where) {
  try {
    const toml::table t = toml::parse("v = " + raw);
    if (const toml::node* n = t.get("v"); n && t.size() == 1) {
      Value v = value_of(*n, where);
      v.text = raw;
      return v;
    }
  } catch (const toml::parse_error&) {
  }
  return {raw, raw, where};
}

void apply_override(Given& given, const std::string& text) {
  const std::string where = "--set " + text;
  const auto eq = text.find('=');
  if (eq == std::string::npos)
    throw InputError(trim(text).empty() ? "--set" : text, "", where, "expected section.key=value");
  const std::string key(trim(std::string_view(text).substr(0, eq)));
  const std::string raw(trim(std::string_view(text).substr(eq + 1)));
  if (key.empty()) throw InputError("--set", text, "", "expected section.key=value: the key before '=' is empty");
  if (!find_spec(key)) throw InputError(key, raw, where, unknown_why(key, false, false));
  // drive.mason and drive.shear_rate are alternatives: an override replaces
  // the file's choice, unless the magnetisation is to follow from both.
  const auto vary = given.find("drive.vary");
  const auto* by = vary == given.end() ? nullptr : std::get_if<std::string>(&vary->second.v);
  const bool both = by && *by == "magnetization";
  const char* other = both ? nullptr
                      : key == "drive.mason" ? "drive.shear_rate"
                      : key == "drive.shear_rate" ? "drive.mason" : nullptr;
  const auto clash = other ? given.find(other) : given.end();
  if (clash != given.end() && !clash->second.where.starts_with("--set")) given.erase(clash);
  given[key] = override_value(raw, where);
}

void read_values(LoadedScene& s, const Given& given) {
  for (const KeySpec& spec : k_keys) {
    const std::string key(spec.key);
    const auto it = given.find(key);
    if (it == given.end()) continue;
    try {
      assign(s.config, spec, it->second);
    } catch (const ValueError& e) {
      throw InputError(key, it->second.text, it->second.where, e.what());
    }
    s.where[key] = it->second.where;
  }
}

bool is_sph(ModelId m) { return !is_one_way(m); }

void require_keys(const LoadedScene& s, const Given& given) {
  for (const KeySpec& spec : k_keys) {
    const std::string key(spec.key);
    if (given.count(key)) continue;
    if (spec.need == Need::required) throw InputError(key, "", s.source, "missing key");
    if (spec.need == Need::sph_models && is_sph(s.config.model))
      throw InputError(key, "", s.source,
                       "missing key (required by model " + std::string(to_string(s.config.model)) +
                           ")");
  }
  const auto mason = given.find("drive.mason");
  const bool rate = given.count("drive.shear_rate") > 0;
  if (s.config.vary == MasonBy::magnetization) {  // Mn at a fixed shear rate: both needed
    for (const char* key : {"drive.mason", "drive.shear_rate"})
      if (!given.count(key))
        throw InputError(key, "", s.locate("drive.vary"),
                         "missing key (drive.vary = \"magnetization\" sets the magnetisation from drive.mason "
                         "and drive.shear_rate: give both)");
    return;
  }
  if (mason == given.end() && !rate)
    throw InputError("drive.mason", "", s.source,
                     "missing key (give drive.mason or drive.shear_rate)");
  if (mason != given.end() && rate)
    throw InputError("drive.mason", mason->second.text, mason->second.where,
                     "give only one of drive.mason and drive.shear_rate (both given, at " +
                         given.at("drive.shear_rate").where + ")");
}

// ---- rules between keys ---------------------------------------------------

using Why = std::optional<std::string>;
Why unless(bool ok, const std::string& why) { return ok ? Why{} : Why{why}; }
double skin_eff(const C& c) { return c.skin > 0 ? c.skin : 0.2 * c.radius; }
double phi_eff(const C& c) { return c.volume_fraction * c.gap / (c.gap - 4 * c.radius); }
constexpr double k_max_packing = 0.35;  // random sequential addition jams near 0.38

struct Rule {
  std::string_view key;                          // the key blamed
  Why (*check)(const C& c, const Given& given);  // a reason when the value is impossible
};

// Single-key ranges passed already (k_keys); a rule may assume the rules above it passed.
const Rule k_rules[] = {
    {"box.gap", [](const C& c, const Given&) {
       return unless(c.gap > 4 * c.radius, "must be > 4*radius = " + format_short(4 * c.radius) +
                                               " m (free centres stay 2*radius from each wall)");
     }},
    {"particles.volume_fraction", [](const C& c, const Given&) {
       return unless(phi_eff(c) <= k_max_packing,
                     "cannot be packed: effective fraction volume_fraction*gap/(gap - 4*radius)"
                     " = " + format_short(phi_eff(c)) + " (limit " + format_short(k_max_packing) + ")");
     }},
    {"particles.magnetization", [](const C& c, const Given& g) {
       return unless(c.magnetization > 0 || !g.count("drive.mason") || c.vary == MasonBy::magnetization,
                     "must be > 0 when drive.mason is given (at M = 0, Mn = 9 eta gdot / (2 mu0 M^2) fixes no "
                     "shear rate; give drive.shear_rate for non-magnetic particles)");
     }},
    {"particles.dipole_cutoff", [](const C& c, const Given&) {
       return unless(c.dipole_cutoff >= 2 * c.radius,
                     "must be >= 2*radius = " + format_short(2 * c.radius) + " m");
     }},
    {"particles.dipole_cutoff", [](const C& c, const Given&) {
       const double half = std::min(c.ly, c.lz) / 2;
       return unless(c.dipole_cutoff + skin_eff(c) <= half,
                     "dipole_cutoff + skin = " + format_short(c.dipole_cutoff + skin_eff(c)) +
                         " m exceeds min(box.ly, box.lz)/2 = " + format_short(half) + " m (minimum image)");
     }},
    {"walls.spacing", [](const C& c, const Given&) {
       return unless(c.wall_spacing <= 2 * c.radius,
                     "must be <= 2*radius = " + format_short(2 * c.radius) + " m");
     }},
    {"drive.warmup_strain", [](const C& c, const Given&) {
       return unless(c.warmup_strain < c.strain, "must be < drive.strain = " + format_short(c.strain));
     }},
    {"numerics.implicit_order", [](const C& c, const Given&) {
       return unless(c.implicit_order == 1 || c.implicit_order == 2, "must be 1 or 2");
     }},
};

void validate(const LoadedScene& s, const Given& given) {
  for (const Rule& r : k_rules) {
    const Why why = r.check(s.config, given);
    if (!why) continue;
    const std::string key(r.key);
    const auto it = given.find(key);
    throw InputError(key, it == given.end() ? "" : it->second.text, s.locate(key), *why);
  }
}

void fill_drive(C& c, const Given& given) {
  if (c.vary == MasonBy::magnetization) {
    c.magnetization = magnetization_from_mason(c.mason, c.viscosity, c.shear_rate);
    return;
  }
  if (given.count("drive.mason"))
    c.shear_rate = shear_rate_from_mason(c.mason, c.viscosity, c.magnetization);
  else  // M = 0 (allowed with shear_rate): Mn is infinite, stated rather than left to a division by zero
    c.mason = c.magnetization > 0 ? mason_from_shear_rate(c.shear_rate, c.viscosity, c.magnetization)
                                  : std::numeric_limits<double>::infinity();
}

// The quantity fill_drive derived must be usable (scene/config.hpp).
void check_drive(const LoadedScene& s, const Given& given) {
  const auto bad = derived_drive_problem(s.config, given.count("drive.mason") > 0);
  if (!bad) return;
  const auto it = given.find(bad->key);
  throw InputError(bad->key, it == given.end() ? "" : it->second.text, s.locate(bad->key), bad->why);
}

}  // namespace

std::string LoadedScene::locate(const std::string& key) const {
  const auto it = where.find(key);
  return it == where.end() ? source : it->second;
}

LoadedScene parse_scene(std::string_view toml_text, const std::string& source_name,
                        const std::vector<std::string>& overrides) {
  Given given = read_document(toml_text, source_name);
  for (const std::string& o : overrides) apply_override(given, o);
  LoadedScene s;
  s.source = source_name;
  read_values(s, given);
  require_keys(s, given);
  validate(s, given);
  fill_drive(s.config, given);
  check_drive(s, given);
  return s;
}

LoadedScene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError("scene file", path, "", "no such file");
  if (fs::is_directory(path, ec)) throw InputError("scene file", path, "", "is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("scene file", path, "", "cannot be read");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return parse_scene(text, path, overrides);
}

}  // namespace mrf
