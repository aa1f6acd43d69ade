#include "mrf/io/timeseries.hpp"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "mrf/error.hpp"
#include "mrf/io/csv.hpp"
#include "mrf/observe/steady_state.hpp"

namespace mrf {

const std::vector<double>& TimeSeriesTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return columns[k];
  std::string have;
  for (const auto& n : names) have += (have.empty() ? "" : ", ") + n;
  throw InputError("column", name, path, "not in the time series (its columns: " + have + ")");
}

TimeSeriesTable read_timeseries(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("file", path, "", "cannot open the time series");
  TimeSeriesTable t;
  t.path = path;
  std::string line;
  if (!std::getline(in, line)) throw InputError("file", path, "", "empty time series (no header)");
  t.names = split_csv_line(line);
  t.columns.resize(t.names.size());
  for (long n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::vector<std::string> f = split_csv_line(line);
    const std::string where = path + ":" + std::to_string(n);
    if (f.size() != t.names.size())
      throw InputError("row", std::to_string(f.size()) + " fields", where,
                       "the header has " + std::to_string(t.names.size()));
    for (std::size_t k = 0; k < f.size(); ++k) {
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(f[k].c_str(), &end);
      if (f[k].empty() || *end != '\0' || errno == ERANGE)
        throw InputError(t.names[k], f[k], where, "not a number");
      t.columns[k].push_back(v);
    }
  }
  return t;
}

std::vector<double> averaging_window(const TimeSeriesTable& t, const std::string& column, double warmup_strain) {
  const std::vector<double>& strain = t.column("strain");
  const std::vector<double>& v = t.column(column);
  std::vector<double> out;
  for (std::size_t r = 0; r < v.size(); ++r) {
    const double start = r == 0 ? 0.0 : strain[r - 1];
    if (start >= warmup_strain * (1 - 1e-12)) out.push_back(v[r]);
  }
  return out;
}

namespace {
// what reanalyse_run reads: the window's strain and the measurements
const std::vector<std::string> k_series_columns = {"time_s", "strain", "stress_total_Pa", "stress_particles_Pa",
                                                   "stress_fluid_Pa", "stress_virial_magnetic_Pa",
                                                   "stress_virial_contact_Pa"};
}  // namespace

std::string window_series_text(const std::string& timeseries_path, double warmup_strain) {
  const TimeSeriesTable t = read_timeseries(timeseries_path);  // validates every row
  std::vector<std::size_t> keep;
  for (const auto& name : k_series_columns)
    for (std::size_t k = 0; k < t.names.size(); ++k)
      if (t.names[k] == name) keep.push_back(k);
  const std::vector<double>& strain = t.column("strain");  // throws, naming the file, when absent
  // the first row of the window (as averaging_window takes it), less one
  std::size_t first = strain.size();
  for (std::size_t r = 0; r < strain.size(); ++r)
    if ((r == 0 ? 0.0 : strain[r - 1]) >= warmup_strain * (1 - 1e-12)) {
      first = r;
      break;
    }
  const std::size_t from = first == 0 ? 0 : first - 1;
  std::ifstream in(timeseries_path);
  std::string line, out;
  auto put = [&](const std::vector<std::string>& f) {
    for (std::size_t k = 0; k < keep.size(); ++k) out += (k ? "," : "") + f[keep[k]];
    out += '\n';
  };
  std::getline(in, line);
  put(split_csv_line(line));
  for (std::size_t r = 0; std::getline(in, line);) {
    if (line.empty()) continue;
    if (r++ >= from) put(split_csv_line(line));
  }
  return out;
}

std::string reanalyse_run(const std::string& dir) {
  const std::filesystem::path d(dir);
  std::ifstream in(d / "summary.json");
  if (!in) throw InputError("directory", dir, "", "no summary.json: not a finished run");
  const nlohmann::json s = nlohmann::json::parse(in, nullptr, false);
  if (s.is_discarded() || !s.contains("warmup_strain") || !s["warmup_strain"].is_number())
    throw InputError("summary.json", (d / "summary.json").string(), "", "unreadable or without warmup_strain");
  const bool archived = !std::filesystem::exists(d / "timeseries.csv") && std::filesystem::exists(d / k_window_series_file);
  const TimeSeriesTable t = read_timeseries((d / (archived ? k_window_series_file : "timeseries.csv")).string());
  const double warmup = s["warmup_strain"].get<double>();
  nlohmann::ordered_json out;
  out["dir"] = dir;
  out["error_estimate_version"] = k_error_estimate_version;
  out["stored_error_estimate_version"] = s.value("error_estimate_version", 1);
  auto put = [&](const std::string& key, const std::vector<double>& w) {
    const BlockAverage b = block_average(w);
    nlohmann::ordered_json m;
    m["samples"] = b.samples;
    m["mean"] = b.mean;
    m["err"] = b.sem;
    m["drift_z"] = b.drift_z;
    m["independent_samples"] = b.independent_samples;
    for (const char* suffix : {"", "_err", "_drift_z"}) {
      const std::string k = key + suffix;
      if (s.contains(k) && s[k].is_number()) m[std::string("stored") + (*suffix ? suffix : "_mean")] = s[k];
    }
    out[key] = m;
  };
  const std::vector<double> total = averaging_window(t, "stress_total_Pa", warmup);
  put("stress_total", total);
  // the policy's second steadiness test, on the total as in the run
  out["steady_mser_discard_fraction"] =
      total.empty() ? 0.0 : static_cast<double>(mser_truncation(total)) / static_cast<double>(total.size());
  if (s.contains("steady_mser_discard_fraction")) out["stored_steady_mser_discard_fraction"] = s["steady_mser_discard_fraction"];
  put("stress_particles", averaging_window(t, "stress_particles_Pa", warmup));
  std::vector<double> vir = averaging_window(t, "stress_virial_magnetic_Pa", warmup);
  const std::vector<double> con = averaging_window(t, "stress_virial_contact_Pa", warmup);
  for (std::size_t r = 0; r < vir.size(); ++r) vir[r] += con[r];
  put("stress_virial", vir);
  return out.dump(2);
}

}  // namespace mrf
