#include "mrf/study/criterion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mrf/coupling/drag_laws.hpp"
#include "mrf/error.hpp"
#include "mrf/io/csv.hpp"

namespace mrf {

SweepTable read_sweep_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("sweep.csv", path, "", "cannot open");
  std::string line;
  std::getline(in, line);
  const auto header = split_csv_line(line);
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
    const auto c = split_csv_line(line);
    if (c.size() != header.size())
      throw InputError("sweep.csv", path + ":" + std::to_string(line_no), "", "row has a different column count");
    if (c[col["status"]] != "ok") continue;
    StressSample s;
    s.mason = std::stod(c[col["mason"]]);
    s.seed = std::stoull(c[col["seed"]]);
    s.stress = std::stod(c[col["stress_total"]]);
    s.err = std::stod(c[col["stress_total_err"]]);
    s.stress_fluid = std::stod(c[col["stress_fluid"]]);
    const auto optional = [&](const char* key, double& v) {
      if (col.count(key) && !c[col[key]].empty()) v = std::stod(c[col[key]]);
    };
    optional("stokes_number", s.stokes);
    optional("reynolds_number", s.reynolds);
    optional("stress_virial_total", s.stress_volume);
    optional("stress_virial_total_err", s.volume_err);
    optional("stress_virial_contact", s.stress_contact);
    optional("stress_virial_contact_err", s.contact_err);
    s.magnetization = std::stod(c[col["magnetization"]]);
    if (first_row) t.magnetization = s.magnetization;
    else if (t.magnetization != s.magnetization) t.magnetization = 0;  // varies from row to row
    first_row = false;
    t.volume_fraction = s.volume_fraction = std::stod(c[col["volume_fraction"]]);
    double gap = 0, radius = 0;
    optional("gap", gap);
    optional("radius", radius);
    if (radius > 0) s.gap_over_radius = gap / radius;
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

double difelice_over_stokes(double volume_fraction) {
  // beta at zero slip is the Re -> 0 limit; the diameter and viscosity cancel
  const double d = 1.0, eta = 1.0;
  return di_felice_drag_coefficient(0.0, 1.0 - volume_fraction, d, 0.0, eta) / (3.0 * k_pi * eta * d);
}

Shortfall predicted_shortfall(const Model1Stresses& s) {
  Shortfall r;
  const auto rel2 = [](double err, double v) { return v != 0 ? (err / v) * (err / v) : 0.0; };
  r.mismatch = 1.0 - s.wall / s.volume;
  r.mismatch_err = std::abs(s.wall / s.volume) * std::sqrt(rel2(s.wall_err, s.wall) + rel2(s.volume_err, s.volume));
  r.drag_ratio = difelice_over_stokes(s.volume_fraction);
  const double k = r.drag_ratio - 1.0;
  const bool drag_term = s.contact > 0;
  r.reference = s.volume + (drag_term ? k * s.contact : 0.0);
  r.reference_err = std::hypot(s.volume_err, drag_term ? k * s.contact_err : 0.0);
  r.value = 1.0 - s.wall / r.reference;
  r.err = std::abs(s.wall / r.reference) * std::sqrt(rel2(s.wall_err, s.wall) + rel2(r.reference_err, r.reference));
  return r;
}

OneWayDdShortfall one_way_dd_shortfall(double wall1, double wall1_err, double volume_dd, double volume_dd_err) {
  const double r = wall1 / volume_dd;
  return {1.0 - r, std::abs(r) * std::hypot(wall1_err / wall1, volume_dd_err / volume_dd)};
}

std::vector<std::string> outside_domain(const RunConditions& c, const CriterionDomain& d) {
  std::vector<std::string> out;
  const auto check = [&out](const char* name, double v, double lo, double hi) {
    char line[96];
    if (v < lo) std::snprintf(line, sizeof line, "%s = %.3g < %.3g", name, v, lo);
    else if (v > hi) std::snprintf(line, sizeof line, "%s = %.3g > %.3g", name, v, hi);
    else return;
    out.emplace_back(line);
  };
  check("phi", c.volume_fraction, d.phi_min, d.phi_max);
  if (c.gap_over_radius > 0) check("gap/R", c.gap_over_radius, d.gap_over_radius_min, d.gap_over_radius_max);
  if (c.gap_over_radius > 0) check("Re_gap", gap_reynolds(c), 0.0, d.gap_reynolds_max);
  check("Mn", c.mason, d.mason_min, d.mason_max);
  check("St", c.stokes, 0.0, d.stokes_max);
  check("Re_p", c.reynolds, 0.0, d.reynolds_max);
  return out;
}

Outcome score_verdict(bool adequate, double deviation, double deviation_err, double level) {
  const double a = std::abs(deviation);
  if (std::abs(a - level) < deviation_err) return Outcome::undecidable;
  const bool within = a < level;
  if (adequate) return within ? Outcome::right_adequate : Outcome::wrong_adequate;
  return within ? Outcome::wrong_not_adequate : Outcome::right_not_adequate;
}

const char* to_string(Outcome o) {
  switch (o) {
    case Outcome::right_adequate: return "right (adequate)";
    case Outcome::right_not_adequate: return "right (not adequate)";
    case Outcome::wrong_adequate: return "WRONG: adequate, but model 1 is off by more";
    case Outcome::wrong_not_adequate: return "wrong (conservative): not adequate, but model 1 is within";
    case Outcome::undecidable: return "undecidable (|D| within one standard error of the level)";
  }
  return "?";
}

void Confusion::add(Outcome o) {
  switch (o) {
    case Outcome::right_adequate: ++right_adequate; break;
    case Outcome::right_not_adequate: ++right_not_adequate; break;
    case Outcome::wrong_adequate: ++wrong_adequate; break;
    case Outcome::wrong_not_adequate: ++wrong_not_adequate; break;
    case Outcome::undecidable: ++undecidable; break;
  }
}

double Confusion::right_fraction() const {
  return decidable() ? static_cast<double>(right_adequate + right_not_adequate) / decidable() : std::nan("");
}

double Confusion::adequate_right_fraction() const {
  const int n = right_adequate + wrong_adequate;
  return n ? static_cast<double>(right_adequate) / n : std::nan("");
}

CriterionScore score_criterion(const std::map<std::string, std::vector<FlowPoint>>& curves) {
  CriterionScore out;
  const std::string model1 = "dem_stokes";
  for (const auto& [key, pts] : curves) {
    if (key.rfind(model1, 0) != 0) continue;
    const auto ref = curves.find("demsph_dd" + key.substr(model1.size()));
    if (ref == curves.end()) continue;
    const auto dd = curves.find("dem_dd" + key.substr(model1.size()));
    for (const Deviation& d : deviation(pts, ref->second)) {
      const FlowPoint& p = *std::find_if(pts.begin(), pts.end(), [&](const FlowPoint& x) { return x.mason == d.mason; });
      if (p.stress_volume == 0) continue;
      ScoredPoint sp;
      sp.curve = key;
      sp.mason = d.mason;
      sp.deviation = d.value;
      sp.deviation_err = d.err;
      sp.shortfall = predicted_shortfall(
          {p.stress, p.err, p.stress_volume, p.volume_err, p.stress_contact, p.contact_err, p.volume_fraction});
      sp.conditions = {p.volume_fraction, p.gap_over_radius, p.mason, p.stokes, p.reynolds};
      sp.seeds = p.seeds;
      sp.outside = outside_domain(sp.conditions);
      if (dd != curves.end()) {
        const auto q = std::find_if(dd->second.begin(), dd->second.end(),
                                    [&](const FlowPoint& x) { return x.mason == d.mason && x.stress_volume != 0; });
        if (q != dd->second.end()) {
          sp.has_dd = true;
          sp.dd = one_way_dd_shortfall(p.stress, p.err, q->stress_volume, q->volume_err);
        }
      }
      for (int k = 0; k < 2; ++k) {
        const double level = k_criterion_levels[k];
        sp.adequate[k] = shortfall_adequate(sp.shortfall, level);
        sp.outcome[k] = score_verdict(sp.adequate[k], d.value, d.err, level);
        sp.mismatch_outcome[k] = score_verdict(std::abs(sp.shortfall.mismatch) < level, d.value, d.err, level);
        out.rule[k].add(sp.outcome[k]);
        out.mismatch_only[k].add(sp.mismatch_outcome[k]);
        if (sp.outside.empty()) out.rule_in_domain[k].add(sp.outcome[k]);
        if (sp.has_dd) {
          sp.dd_outcome[k] = score_verdict(std::abs(sp.dd.value) < level, d.value, d.err, level);
          out.one_way_dd[k].add(sp.dd_outcome[k]);
        }
      }
      out.points.push_back(sp);
    }
  }
  return out;
}

CriterionVerdict apply_criterion(double share, double s10, double s20) {
  return {share, share < s10, share < s20};
}

}  // namespace mrf
