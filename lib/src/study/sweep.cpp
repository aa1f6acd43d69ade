#include "mrf/study/sweep.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "mrf/error.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/io/quantity.hpp"
#include "mrf/scene/config.hpp"

namespace mrf {
namespace {

std::string where_of(const toml::node& n, const std::string& source) {
  return source + ":" + std::to_string(n.source().begin.line);
}

std::string text_of(const toml::node& n) {
  std::ostringstream os;
  os << toml::toml_formatter{n};
  return os.str();
}

const toml::array& need_array(const toml::table& t, const char* key, const std::string& section,
                              const std::string& source) {
  const toml::node* n = t.get(key);
  if (!n) throw InputError(section + "." + key, "", source, "missing");
  const toml::array* a = n->as_array();
  if (!a || a->empty()) throw InputError(section + "." + key, text_of(*n), where_of(*n, source), "expected a non-empty array");
  return *a;
}

std::vector<std::string> strings(const toml::array& a, const std::string& key, const std::string& source) {
  std::vector<std::string> out;
  for (const auto& e : a) {
    const auto* s = e.as_string();
    if (!s) throw InputError(key, text_of(e), where_of(e, source), "expected a string");
    out.push_back(s->get());
  }
  return out;
}

std::vector<std::uint64_t> seeds(const toml::array& a, const std::string& key, const std::string& source) {
  std::vector<std::uint64_t> out;
  for (const auto& e : a) {
    const auto v = e.value<std::int64_t>();
    if (!v || *v < 0) throw InputError(key, text_of(e), where_of(e, source), "expected a non-negative integer");
    out.push_back(static_cast<std::uint64_t>(*v));
  }
  return out;
}

void check_models(const std::vector<std::string>& models, const toml::node& n, const std::string& key,
                  const std::string& source) {
  for (const auto& m : models) {
    bool known = false;
    for (ModelId id : {ModelId::dem_stokes, ModelId::demsph_stokes, ModelId::demsph_dd, ModelId::dem_dd})
      known |= m == to_string(id);
    if (!known)
      throw InputError(key, "\"" + m + "\"", where_of(n, source),
                       "unknown model; expected dem_stokes, demsph_stokes, demsph_dd or dem_dd");
  }
}

double positive_number(const toml::node& n, const std::string& key, const std::string& source) {
  const auto v = n.value<double>();
  if (!v || !(*v > 0)) throw InputError(key, text_of(n), where_of(n, source), "expected a positive number");
  return *v;
}

// Folder names only: 4 digits. The point's scene gets the exact value (format_number).
std::string mason_label(double mn) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", mn);
  return buf;
}

void parse_variants(const toml::node& variants, const std::string& source, SweepSpec& s) {
  const auto* arr = variants.as_array();
  if (!arr) throw InputError("variant", "", where_of(variants, source), "expected [[variant]] tables");
  for (const auto& e : *arr) {
    const auto* t = e.as_table();
    if (!t) throw InputError("variant", text_of(e), where_of(e, source), "expected a table");
    SweepVariant v;
    for (const auto& [k, val] : *t) {
      const std::string key(k.str());
      if (key == "name") {
        const auto* n = val.as_string();
        const bool safe = n && !n->get().empty() && std::all_of(n->get().begin(), n->get().end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-';
        });
        if (!safe || n->get() == "." || n->get() == "..")
          throw InputError("variant.name", text_of(val), where_of(val, source),
                           "expected a folder-safe name (letters, digits, _ . -)");
        v.name = n->get();
      } else if (key == "set") {
        const auto* a = val.as_array();
        if (!a) throw InputError("variant.set", text_of(val), where_of(val, source), "expected an array of section.key=value");
        v.set = strings(*a, "variant.set", source);
      } else if (key == "models") {
        const auto* a = val.as_array();
        if (!a || a->empty())
          throw InputError("variant.models", text_of(val), where_of(val, source), "expected a non-empty array");
        v.models = strings(*a, "variant.models", source);
        for (const auto& m : v.models)
          if (std::find(s.models.begin(), s.models.end(), m) == s.models.end())
            throw InputError("variant.models", "\"" + m + "\"", where_of(val, source), "not one of sweep.models");
      } else if (key == "mason") {
        const auto* a = val.as_array();
        if (!a || a->empty())
          throw InputError("variant.mason", text_of(val), where_of(val, source), "expected a non-empty array");
        for (const auto& m : *a) v.mason.push_back(positive_number(m, "variant.mason", source));
      } else {
        throw InputError("variant." + key, text_of(val), where_of(val, source), "unknown key");
      }
    }
    if (v.name.empty()) throw InputError("variant.name", "", where_of(e, source), "missing");
    for (const auto& other : s.variants)
      if (other.name == v.name) throw InputError("variant.name", "\"" + v.name + "\"", where_of(e, source), "used twice");
    if (v.mason.empty() && s.mason.empty())
      throw InputError("variant.mason", "", where_of(e, source), "missing, and the sweep has no sweep.mason to fall back on");
    s.variants.push_back(std::move(v));
  }
}

}  // namespace

SweepSpec parse_sweep(const std::string& toml_text, const std::string& source, const std::string& base_dir) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    throw InputError("(syntax)", "", source + ":" + std::to_string(e.source().begin.line), std::string(e.description()));
  }
  for (const auto& [k, v] : root)
    if (k.str() != "sweep" && k.str() != "rule" && k.str() != "variant")
      throw InputError(std::string(k.str()), "", where_of(v, source),
                       "unknown section; expected [sweep], [[rule]] or [[variant]]");
  const toml::table* sw = root["sweep"].as_table();
  if (!sw) throw InputError("sweep", "", source, "missing [sweep] table");
  SweepSpec s;
  s.source = source;
  for (const auto& [k, v] : *sw) {
    const std::string key(k.str());
    if (key != "scene" && key != "models" && key != "mason" && key != "seeds" && key != "set")
      throw InputError("sweep." + key, text_of(v), where_of(v, source), "unknown key");
  }
  const toml::node* scene = sw->get("scene");
  if (!scene || !scene->is_string()) throw InputError("sweep.scene", "", source, "missing (path of the base scene)");
  s.scene_path = (std::filesystem::path(base_dir) / scene->as_string()->get()).lexically_normal().string();
  if (!std::filesystem::exists(s.scene_path))
    throw InputError("sweep.scene", text_of(*scene), where_of(*scene, source), "no such file: " + s.scene_path);
  const auto& models = need_array(*sw, "models", "sweep", source);
  s.models = strings(models, "sweep.models", source);
  check_models(s.models, models, "sweep.models", source);
  if (sw->get("mason") || !root.get("variant"))
    for (const auto& e : need_array(*sw, "mason", "sweep", source)) s.mason.push_back(positive_number(e, "sweep.mason", source));
  s.seeds = seeds(need_array(*sw, "seeds", "sweep", source), "sweep.seeds", source);
  if (const toml::node* set = sw->get("set")) {
    if (!set->as_array())
      throw InputError("sweep.set", text_of(*set), where_of(*set, source), "expected an array of overrides");
    s.set = strings(*set->as_array(), "sweep.set", source);
  }
  if (const toml::node* rules = root.get("rule")) {
    const auto* arr = rules->as_array();
    if (!arr) throw InputError("rule", "", where_of(*rules, source), "expected [[rule]] tables");
    for (const auto& e : *arr) {
      const auto* t = e.as_table();
      if (!t) throw InputError("rule", text_of(e), where_of(e, source), "expected a table");
      SweepRule r;
      for (const auto& [k, v] : *t) {
        const std::string key(k.str());
        if (key == "mason_min") r.mason_min = positive_number(v, "rule.mason_min", source);
        else if (key == "mason_max") r.mason_max = positive_number(v, "rule.mason_max", source);
        else if (key == "models") {
          const auto* a = v.as_array();
          if (!a) throw InputError("rule.models", text_of(v), where_of(v, source), "expected an array of model names");
          r.models = strings(*a, "rule.models", source);
          check_models(r.models, v, "rule.models", source);
        } else if (key == "seeds") {
          const auto* a = v.as_array();
          if (!a) throw InputError("rule.seeds", text_of(v), where_of(v, source), "expected an array of seeds");
          r.seeds = seeds(*a, "rule.seeds", source);
        } else if (key == "set") {
          const auto* a = v.as_array();
          if (!a) throw InputError("rule.set", text_of(v), where_of(v, source), "expected an array of section.key=value");
          r.set = strings(*a, "rule.set", source);
        } else if (key == "variants") {
          const auto* a = v.as_array();
          if (!a || a->empty())
            throw InputError("rule.variants", text_of(v), where_of(v, source), "expected a non-empty array of variant names");
          r.variants = strings(*a, "rule.variants", source);
        } else {
          throw InputError("rule." + key, text_of(v), where_of(v, source), "unknown key");
        }
      }
      if (r.set.empty()) throw InputError("rule.set", "", where_of(e, source), "a rule needs overrides to apply");
      s.rules.push_back(std::move(r));
    }
  }
  if (const toml::node* variants = root.get("variant")) parse_variants(*variants, source, s);
  for (const auto& r : s.rules)
    for (const auto& name : r.variants)
      if (std::none_of(s.variants.begin(), s.variants.end(), [&](const SweepVariant& v) { return v.name == name; }))
        throw InputError("rule.variants", "\"" + name + "\"", source, "not the name of a [[variant]] of this sweep");
  // every point its own folder: a repeated seed, or two Mn that print alike
  // to 4 digits, would have two points run in (and tabulated from) one
  std::set<std::string> folders;
  for (const SweepPoint& p : sweep_points(s))
    if (!folders.insert(p.dir).second)
      throw InputError("sweep", p.dir, source,
                       "two points of the grid share this folder (a repeated seed, model or variant, or two Mason "
                       "numbers equal to 4 significant digits)");
  return s;
}

SweepSpec load_sweep(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("sweep", path, "", "cannot open the sweep file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_sweep(text.str(), path, std::filesystem::path(path).parent_path().string());
}

std::vector<SweepPoint> sweep_points(const SweepSpec& spec) {
  std::vector<SweepPoint> out;
  const std::vector<SweepVariant> none{SweepVariant{}};
  const auto& variants = spec.variants.empty() ? none : spec.variants;
  for (const auto& model : spec.models)
    for (const auto& v : variants) {
      if (!v.models.empty() && std::find(v.models.begin(), v.models.end(), model) == v.models.end()) continue;
      for (double mn : v.mason.empty() ? spec.mason : v.mason)
        for (std::uint64_t seed : spec.seeds) {
          SweepPoint p;
          p.index = out.size();
          p.model = model;
          p.mason = mn;
          p.seed = seed;
          p.variant = v.name;
          p.sets = spec.set;
          const auto applies = [&](const SweepRule& r) {
            const bool model_ok =
                r.models.empty() || std::find(r.models.begin(), r.models.end(), model) != r.models.end();
            const bool mn_ok = (r.mason_min == 0 || mn >= r.mason_min) && (r.mason_max == 0 || mn <= r.mason_max);
            const bool seed_ok = r.seeds.empty() || std::find(r.seeds.begin(), r.seeds.end(), seed) != r.seeds.end();
            return model_ok && mn_ok && seed_ok;
          };
          for (const auto& r : spec.rules)
            if (r.variants.empty() && applies(r)) p.sets.insert(p.sets.end(), r.set.begin(), r.set.end());
          p.sets.insert(p.sets.end(), v.set.begin(), v.set.end());
          for (const auto& r : spec.rules)  // rules that refine a variant come after its overrides
            if (std::find(r.variants.begin(), r.variants.end(), v.name) != r.variants.end() && applies(r))
              p.sets.insert(p.sets.end(), r.set.begin(), r.set.end());
          p.sets.push_back("scene.model=\"" + model + "\"");
          p.sets.push_back("drive.mason=" + format_number(mn));  // reads back exactly: the run and sweep.csv agree
          p.sets.push_back("scene.seed=" + std::to_string(seed));
          p.dir = model + "/" + (v.name.empty() ? "" : v.name + "/") + "mn_" + mason_label(mn) + "_seed_" +
                  std::to_string(seed);
          out.push_back(std::move(p));
        }
    }
  return out;
}

std::vector<std::size_t> points_of_rank(std::size_t n_points, int rank, int size) {
  if (size < 1 || rank < 0 || rank >= size)
    throw std::invalid_argument("points_of_rank: rank " + std::to_string(rank) + " of " + std::to_string(size));
  std::vector<std::size_t> out;
  for (std::size_t i = static_cast<std::size_t>(rank); i < n_points; i += static_cast<std::size_t>(size)) out.push_back(i);
  return out;
}

RankInfo rank_from_environment() {
  auto read = [](const char* a, const char* b) -> const char* {
    if (const char* v = std::getenv(a)) return v;
    return std::getenv(b);
  };
  const char* r = read("OMPI_COMM_WORLD_RANK", "PMI_RANK");
  const char* n = read("OMPI_COMM_WORLD_SIZE", "PMI_SIZE");
  RankInfo info;
  if (r && n) {
    info.rank = std::atoi(r);
    info.size = std::atoi(n);
    if (info.size < 1 || info.rank < 0 || info.rank >= info.size) info = RankInfo{};
  }
  return info;
}

namespace {
enum class Record { absent, readable, damaged };
Record record_state(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return Record::absent;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  return !j.is_discarded() && j.is_object() ? Record::readable : Record::damaged;
}
}  // namespace

bool point_finished(const std::string& point_dir) {
  const std::filesystem::path d(point_dir);
  return record_state(d / "summary.json") == Record::readable || record_state(d / "failure.json") == Record::readable;
}

bool point_record_damaged(const std::string& point_dir) {
  const std::filesystem::path d(point_dir);
  return record_state(d / "summary.json") == Record::damaged || record_state(d / "failure.json") == Record::damaged;
}

double point_strain_reached(const std::string& point_dir) {
  const std::filesystem::path d(point_dir);
  if (!std::filesystem::exists(d / "checkpoint.bin")) return 0.0;
  std::ifstream in(d / "timeseries.csv", std::ios::binary);
  if (!in) return 0.0;
  // the last complete line is in the file's last few kB (a row is ~200 bytes)
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg(), tail = std::min<std::streamoff>(size, 8192);
  std::string text(static_cast<std::size_t>(tail), '\0');
  in.seekg(size - tail);
  in.read(text.data(), tail);
  const std::size_t end = text.find_last_of('\n');
  if (end == std::string::npos || end == 0) return 0.0;
  const std::size_t begin = text.find_last_of('\n', end - 1);
  if (begin == std::string::npos) return 0.0;  // the header alone (or a row longer than the tail)
  const std::string row = text.substr(begin + 1, end - begin - 1);
  const std::size_t comma = row.find(',');  // time_s,strain,...
  if (comma == std::string::npos) return 0.0;
  char* stop = nullptr;
  const double strain = std::strtod(row.c_str() + comma + 1, &stop);
  return stop != row.c_str() + comma + 1 && std::isfinite(strain) && strain > 0 ? strain : 0.0;
}

std::string sweep_csv(const std::vector<SweepPoint>& points, const std::string& out_dir, const SweepSpec* spec) {
  static const char* numbers[] = {"shear_rate", "strain", "warmup_strain", "stress_total", "stress_total_err",
                                  "stress_total_drift_z", "steady_mser_discard_fraction", "stress_particles", "stress_particles_err", "stress_fluid",
                                  "stress_virial", "stress_virial_err", "stress_virial_total", "stress_virial_total_err",
                                  "stress_virial_magnetic",
                                  "stress_virial_contact", "stress_virial_contact_err", "n_particles", "n_fluid", "dt", "steps", "wall_seconds",
                                  "stokes_number", "reynolds_number", "max_overlap_over_radius", "volume_fraction",
                                  "magnetization", "youngs_modulus", "viscosity", "fluid_density", "gap", "radius",
                                  "spanning_fraction", "sph_h", "implicit_newton_iterations", "implicit_linear_iterations",
                                  "error_estimate_version", "stress_total_independent_samples",
                                  "stress_particles_drift_z", "stress_particles_independent_samples", "cpu_seconds"};
  std::ostringstream csv;
  csv.precision(10);
  csv << "model,mason,seed,status";
  for (const char* k : numbers) csv << "," << k;
  csv << ",variant,integrator,dir\n";
  for (const auto& p : points) {
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    nlohmann::json j;
    std::string status;
    if (spec && point_stale(*spec, p, dir)) {
      status = "stale";
    } else if (std::ifstream in(dir / "summary.json"); in) {
      j = nlohmann::json::parse(in, nullptr, false);
      status = j.is_discarded() ? "unreadable" : "ok";
    } else if (std::filesystem::exists(dir / "failure.json")) {
      status = "failed";
    } else {
      continue;
    }
    csv << p.model << "," << format_number(p.mason) << "," << p.seed << "," << status;
    for (const char* k : numbers) {
      csv << ",";
      if (status == "ok" && j.contains(k) && j[k].is_number()) csv << j[k].get<double>();
    }
    csv << "," << p.variant << "," << (status == "ok" && j.contains("integrator") ? j["integrator"].get<std::string>() : "")
        << "," << p.dir
        << "\n";
  }
  return csv.str();
}

std::size_t write_sweep_csv(const std::vector<SweepPoint>& points, const std::string& out_dir, const SweepSpec* spec) {
  std::filesystem::create_directories(out_dir);
  write_file_atomic((std::filesystem::path(out_dir) / "sweep.csv").string(), sweep_csv(points, out_dir, spec));
  std::size_t done = 0;
  for (const auto& p : points) {
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    done += point_finished(dir.string()) && !(spec && point_stale(*spec, p, dir)) ? 1 : 0;
  }
  return done;
}

}  // namespace mrf
