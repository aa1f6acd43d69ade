#include "mrf/study/criterion.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mrf/error.hpp"

namespace mrf {

namespace {
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}
}  // namespace

SweepTable read_sweep_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("sweep.csv", path, "", "cannot open");
  std::string line;
  std::getline(in, line);
  const auto header = split(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* k : {"model", "mason", "seed", "status", "stress_total", "stress_total_err", "stress_fluid",
                        "magnetization", "volume_fraction"})
    if (!col.count(k)) throw InputError("sweep.csv", path, "", std::string("missing column ") + k);
  SweepTable t;
  double inferred = 0;  // eta from a dem_stokes row, for a sweep.csv without viscosity
  std::string inferred_from;
  int line_no = 1;
  bool first_row = true;
  while (std::getline(in, line)) {
    ++line_no;
    const auto c = split(line);
    if (c.size() != header.size())
      throw InputError("sweep.csv", path + ":" + std::to_string(line_no), "", "row has a different column count");
    if (c[col["status"]] != "ok") continue;
    StressSample s;
    s.mason = std::stod(c[col["mason"]]);
    s.seed = std::stoull(c[col["seed"]]);
    s.stress = std::stod(c[col["stress_total"]]);
    s.err = std::stod(c[col["stress_total_err"]]);
    s.stress_fluid = std::stod(c[col["stress_fluid"]]);
    if (col.count("stokes_number") && !c[col["stokes_number"]].empty()) s.stokes = std::stod(c[col["stokes_number"]]);
    if (col.count("reynolds_number") && !c[col["reynolds_number"]].empty())
      s.reynolds = std::stod(c[col["reynolds_number"]]);
    if (col.count("stress_virial_total") && !c[col["stress_virial_total"]].empty())
      s.stress_volume = std::stod(c[col["stress_virial_total"]]);
    s.magnetization = std::stod(c[col["magnetization"]]);
    if (first_row) t.magnetization = s.magnetization;
    else if (t.magnetization != s.magnetization) t.magnetization = 0;  // varies from row to row
    first_row = false;
    t.volume_fraction = std::stod(c[col["volume_fraction"]]);
    if (t.viscosity == 0 && col.count("viscosity") && !c[col["viscosity"]].empty())
      t.viscosity = std::stod(c[col["viscosity"]]);
    if (t.fluid_density == 0 && col.count("fluid_density") && !c[col["fluid_density"]].empty())
      t.fluid_density = std::stod(c[col["fluid_density"]]);
    // no viscosity column (sweep.csv of an earlier mrf): tau_fluid of model 1 is eta gdot
    if (inferred == 0 && c[col["model"]] == "dem_stokes" && col.count("shear_rate") && !c[col["shear_rate"]].empty()) {
      const double gdot = std::stod(c[col["shear_rate"]]);
      if (gdot > 0 && s.stress_fluid > 0) {
        inferred = s.stress_fluid / gdot;
        inferred_from = path + ":" + std::to_string(line_no);
      }
    }
    // a sweep with variants: one flow curve per model and variant
    const std::string variant = col.count("variant") ? c[col["variant"]] : "";
    t.samples[c[col["model"]] + (variant.empty() ? "" : "@" + variant)].push_back(s);
  }
  if (t.viscosity > 0 || t.samples.empty()) return t;
  if (inferred > 0) {
    t.viscosity = inferred;
    char eta[32];
    std::snprintf(eta, sizeof eta, "%.6g", inferred);
    t.viscosity_note = "sweep.csv has no viscosity value (written by an mrf whose summary.json lacked it): eta = " +
                       std::string(eta) + " Pa s inferred as stress_fluid/shear_rate of the dem_stokes row " +
                       inferred_from;
    return t;
  }
  throw InputError("sweep.csv", path, "",
                   "has no viscosity value (no or an empty viscosity column: written by an mrf whose summary.json lacked "
                   "the fluid viscosity) and no "
                   "ok dem_stokes row to infer it from (model 1's fluid stress is eta * shear_rate; the SPH models' is "
                   "not); the flow curves need it: rerun the points with this mrf (summary.json then carries "
                   "viscosity) or add a viscosity column in Pa s");
}

std::vector<Deviation> deviation(const std::vector<FlowPoint>& model, const std::vector<FlowPoint>& ref) {
  std::vector<Deviation> out;
  for (const auto& m : model)
    for (const auto& r : ref)
      if (m.mason == r.mason && r.stress != 0 && m.stress != 0) {
        Deviation d;
        d.mason = m.mason;
        const double q = m.stress / r.stress;
        d.value = q - 1.0;
        d.err = std::abs(q) * std::sqrt(std::pow(m.err / m.stress, 2) + std::pow(r.err / r.stress, 2));
        d.share = m.stress_fluid / m.stress;
        d.mismatch = m.stress_volume != 0 ? 1.0 - m.stress / m.stress_volume : 0.0;
        d.volume_value = m.stress_volume != 0 ? m.stress_volume / r.stress - 1.0 : 0.0;
        d.stokes = m.stokes;
        d.reynolds = m.reynolds;
        out.push_back(d);
      }
  return out;
}

Crossing first_crossing(const std::vector<Deviation>& d, double level) {
  Crossing c;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double a = std::abs(d[i].value);
    if (a < level) continue;
    c.found = true;
    if (i == 0) {  // already above at the lowest Mn: the crossing lies below the sweep
      c.below_range = true;
      c.mason = d[0].mason;
      c.share = d[0].share;
      return c;
    }
    const double a0 = std::abs(d[i - 1].value);
    const double w = (level - a0) / (a - a0);
    c.mason = std::exp(std::log(d[i - 1].mason) + w * (std::log(d[i].mason) - std::log(d[i - 1].mason)));
    c.share = d[i - 1].share + w * (d[i].share - d[i - 1].share);
    return c;
  }
  return c;
}

bool consistency_adequate(double mismatch, double reynolds, double level) {
  return std::abs(mismatch) < level && reynolds < k_criterion_max_reynolds;
}

CriterionVerdict apply_criterion(double share, double s10, double s20) {
  return {share, share < s10, share < s20};
}

}  // namespace mrf
