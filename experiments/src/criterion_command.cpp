// `mrf criterion PATH`: flow-curve fits, deviations from model 3 and the
// applicability verdict of model 1 for a sweep (PATH/sweep.csv) or a single
// run (PATH/summary.json). See lib/include/mrf/study/criterion.hpp.
#include "criterion_command.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "mrf/error.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/study/criterion.hpp"

namespace {

using nlohmann::ordered_json;

ordered_json fit_json(const mrf::FlowFit& f) {
  return {{"ok", f.ok},
          {"message", f.message},
          {"eta_inf", f.eta_inf},
          {"eta_inf_err", f.eta_inf_err},
          {"mason_star", f.mason_star},
          {"mason_star_err", f.mason_star_err},
          {"exponent", f.exponent},
          {"exponent_err", f.exponent_err},
          {"slope", f.slope},
          {"slope_err", f.slope_err},
          {"chi2_dof", f.chi2_dof},
          {"dof", f.dof}};
}

struct Thresholds {
  double s10 = 0, s20 = 0;
  std::string source;
};

Thresholds read_thresholds(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw mrf::InputError("--thresholds", path, "", "cannot open the thresholds file");
  const auto j = nlohmann::json::parse(in);
  // a thresholds file, or the criterion.json of a sweep that derived them
  const auto& t = j.contains("derived_thresholds") ? j["derived_thresholds"] : j;
  if (!t.contains("share_10") || !t.contains("share_20"))
    throw mrf::InputError("--thresholds", path, "", "has no share_10/share_20 (and no derived_thresholds)");
  return {t["share_10"].get<double>(), t["share_20"].get<double>(), path};
}

void print_verdict(const char* what, double share, const Thresholds& t) {
  const auto v = mrf::apply_criterion(share, t.s10, t.s20);
  std::printf("%s: hydrodynamic share s = tau_fluid/tau_total = %.3g -> model 1 %s within 10 %% (s < %.3g), %s within 20 %% "
              "(s < %.3g) [thresholds from %s]\n",
              what, share, v.adequate_10 ? "ADEQUATE" : "NOT adequate", t.s10, v.adequate_20 ? "ADEQUATE" : "NOT adequate",
              t.s20, t.source.c_str());
}

int run_directory(const std::string& dir, const Thresholds* t) {
  std::ifstream in(dir + "/summary.json");
  const auto j = nlohmann::json::parse(in);
  if (j.at("model") != "dem_stokes")
    throw mrf::InputError("model", j.at("model").dump(), dir + "/summary.json",
                          "the criterion is read off a model-1 (dem_stokes) run");
  const double total = j.at("stress_total").get<double>();
  const double share = j.at("stress_fluid").get<double>() / total;
  const auto num = [&j](const char* k) { return j.contains(k) && j[k].is_number() ? j[k].get<double>() : 0.0; };
  if (j.contains("stress_virial_total") && j.contains("stress_virial_contact")) {
    mrf::Model1Stresses st{total, num("stress_total_err"), num("stress_virial_total"), num("stress_virial_total_err"),
                           num("stress_virial_contact"), num("stress_virial_contact_err"), num("volume_fraction")};
    const auto sf = mrf::predicted_shortfall(st);
    const mrf::RunConditions rc{st.volume_fraction, num("radius") > 0 ? num("gap") / num("radius") : 0.0,
                                num("mason"), num("stokes_number"), num("reynolds_number")};
    std::printf("%s: model 1 (dem_stokes) predicted shortfall against the two-way DD model\n"
                "  delta = 1 - tau_wall/tau_ref = %.3f +- %.3f -> model 1 %s within 10 %%, %s within 20 %%\n"
                "  tau_wall = %.4g +- %.2g Pa; tau_ref = tau_volume + (g - 1) max(tau_contact, 0) = %.4g +- %.2g Pa\n"
                "  m = 1 - tau_wall/tau_volume = %.3f +- %.3f; tau_contact = %.4g +- %.2g Pa; g(phi = %.3g) = %.3f\n"
                "  St = %.3g, Re_p = %.3g, Re_gap = %s, Mn = %.3g, gap/R = %s, gap-spanning fraction = %s\n",
                dir.c_str(), sf.value, sf.err, mrf::shortfall_adequate(sf, 0.1) ? "ADEQUATE" : "NOT adequate",
                mrf::shortfall_adequate(sf, 0.2) ? "ADEQUATE" : "NOT adequate", st.wall, st.wall_err, sf.reference,
                sf.reference_err, sf.mismatch, sf.mismatch_err, st.contact, st.contact_err, st.volume_fraction,
                sf.drag_ratio, rc.stokes, rc.reynolds,
                rc.gap_over_radius > 0 ? std::to_string(mrf::gap_reynolds(rc)).c_str() : "unknown", rc.mason,
                rc.gap_over_radius > 0 ? std::to_string(rc.gap_over_radius).c_str() : "unknown (no radius in summary.json)",
                j.contains("spanning_fraction") ? std::to_string(num("spanning_fraction")).c_str() : "not measured");
    const mrf::CriterionDomain dom;
    std::printf("  tested on (experiments/sweeps/criterion_heldout*.toml): phi %.2g-%.2g, gap/R %.3g-%.3g, Mn %.2g-%.2g, "
                "St <= %.2g, Re_p <= %.2g, Re_gap = rho_f gdot gap^2/eta <= %.3g\n",
                dom.phi_min, dom.phi_max, dom.gap_over_radius_min, dom.gap_over_radius_max, dom.mason_min,
                dom.mason_max, dom.stokes_max, dom.reynolds_max, dom.gap_reynolds_max);
    for (const auto& w : mrf::outside_domain(rc, dom))
      std::printf("  OUTSIDE the tested range: %s (the verdict is an extrapolation)\n", w.c_str());
  }
  if (j.contains("stress_virial_total")) {
    const double m = 1.0 - total / j["stress_virial_total"].get<double>();
    const double re = j.at("reynolds_number").get<double>();
    std::printf("%s: [earlier, provisional rule] m = %.3f, Re_p = %.3g -> model 1 %s within "
                "10 %%, %s within 20 %% (|m| < level and Re_p < %.2g)\n",
                dir.c_str(), m, re, mrf::consistency_adequate(m, re, 0.1) ? "ADEQUATE" : "NOT adequate",
                mrf::consistency_adequate(m, re, 0.2) ? "ADEQUATE" : "NOT adequate", mrf::k_criterion_max_reynolds);
  }
  if (!t) {
    std::printf("%s: hydrodynamic share s = %.3g (give --thresholds FILE for the share verdict)\n", dir.c_str(), share);
    return 0;
  }
  print_verdict(dir.c_str(), share, *t);
  return 0;
}

// The pre-registered criterion scored against model 3 (mrf::score_criterion)
// as criterion.json holds it, with one line per level on stdout.
ordered_json preregistered_json(const mrf::CriterionScore& sc) {
  ordered_json rows = ordered_json::array();
  for (const auto& p : sc.points) {
    ordered_json r{{"curve", p.curve},
                   {"mason", p.mason},
                   {"deviation", p.deviation},
                   {"deviation_err", p.deviation_err},
                   {"shortfall", p.shortfall.value},
                   {"shortfall_err", p.shortfall.err},
                   {"mismatch", p.shortfall.mismatch},
                   {"mismatch_err", p.shortfall.mismatch_err},
                   {"drag_ratio", p.shortfall.drag_ratio},
                   {"volume_fraction", p.conditions.volume_fraction},
                   {"gap_over_radius", p.conditions.gap_over_radius},
                   {"stokes", p.conditions.stokes},
                   {"reynolds", p.conditions.reynolds},
                   {"gap_reynolds", mrf::gap_reynolds(p.conditions)},
                   {"seeds", p.seeds}};
    if (!p.outside.empty()) r["outside_domain"] = p.outside;
    if (p.has_dd) {
      r["one_way_dd_shortfall"] = p.dd.value;
      r["one_way_dd_shortfall_err"] = p.dd.err;
      for (int k = 0; k < 2; ++k)
        r[std::string("one_way_dd_outcome") + (k == 0 ? "_10" : "_20")] = mrf::to_string(p.dd_outcome[k]);
    }
    for (int k = 0; k < 2; ++k) {
      const std::string tag = k == 0 ? "_10" : "_20";
      r["adequate" + tag] = p.adequate[k];
      r["outcome" + tag] = mrf::to_string(p.outcome[k]);
      r["mismatch_only_outcome" + tag] = mrf::to_string(p.mismatch_outcome[k]);
    }
    rows.push_back(r);
  }
  const auto matrix = [](const mrf::Confusion& c) {
    return ordered_json{{"right_adequate", c.right_adequate},
                        {"right_not_adequate", c.right_not_adequate},
                        {"wrong_adequate", c.wrong_adequate},
                        {"wrong_not_adequate", c.wrong_not_adequate},
                        {"undecidable", c.undecidable},
                        {"right_fraction", c.decidable() ? ordered_json(c.right_fraction()) : ordered_json()},
                        {"adequate_right_fraction", c.right_adequate + c.wrong_adequate
                                                        ? ordered_json(c.adequate_right_fraction())
                                                        : ordered_json()}};
  };
  ordered_json out{{"rule", "model 1 adequate at a when |1 - tau_wall/(tau_volume + (g(phi) - 1) max(tau_contact, 0))| < a"},
                   {"points", rows}};
  for (int k = 0; k < 2; ++k) {
    const std::string tag = k == 0 ? "_10" : "_20";
    const auto& r = sc.rule[k];
    const auto& m = sc.mismatch_only[k];
    out["confusion" + tag] = matrix(r);
    out["mismatch_only_confusion" + tag] = matrix(m);
    out["in_domain_confusion" + tag] = matrix(sc.rule_in_domain[k]);
    if (sc.one_way_dd[k].decidable() + sc.one_way_dd[k].undecidable > 0)
      out["one_way_dd_confusion" + tag] = matrix(sc.one_way_dd[k]);
    if (!rows.empty())
      std::printf("pre-registered criterion at %2.0f %%: %d right (%d of them adequate), %d wrong 'adequate', %d wrong "
                  "'not adequate', %d undecidable; |m| alone: %d right, %d wrong 'adequate', %d wrong 'not adequate'\n",
                  100 * mrf::k_criterion_levels[k], r.right_adequate + r.right_not_adequate, r.right_adequate,
                  r.wrong_adequate, r.wrong_not_adequate, r.undecidable, m.right_adequate + m.right_not_adequate,
                  m.wrong_adequate, m.wrong_not_adequate);
  }
  return out;
}

}  // namespace

int criterion_command(const std::string& path, const std::string& thresholds_path) {
  std::optional<Thresholds> t;
  if (!thresholds_path.empty()) t = read_thresholds(thresholds_path);
  if (std::filesystem::exists(path + "/summary.json") && !std::filesystem::exists(path + "/sweep.csv"))
    return run_directory(path, t ? &*t : nullptr);
  const mrf::SweepTable table = mrf::read_sweep_csv(path + "/sweep.csv");
  ordered_json out;
  out["mason_convention"] = "Mn = 9 eta gdot / (2 mu0 M^2)";
  if (table.magnetization > 0) out["magnetization"] = table.magnetization;
  else out["magnetization_note"] = "varies with Mn (drive.vary = magnetization): see each point";
  out["viscosity"] = table.viscosity;
  out["fluid_density"] = table.fluid_density;
  if (!table.viscosity_note.empty()) {
    out["viscosity_note"] = table.viscosity_note;
    std::fprintf(stderr, "mrf criterion: note: %s\n", table.viscosity_note.c_str());
  }
  out["volume_fraction"] = table.volume_fraction;
  std::map<std::string, std::vector<mrf::FlowPoint>> curves;
  for (const auto& [model, samples] : table.samples) {
    const auto pts = mrf::seed_average(samples);
    curves[model] = pts;
    std::vector<double> mn, er, ee;
    ordered_json rows = ordered_json::array();
    for (const auto& p : pts) {
      const double k = mrf::relative_viscosity(1.0, p.mason, table.viscosity, p.magnetization);
      mn.push_back(p.mason);
      er.push_back(p.stress * k);
      ee.push_back(std::max(p.err, 1e-12 * std::abs(p.stress)) * k);
      rows.push_back({{"mason", p.mason}, {"magnetization", p.magnetization}, {"stress", p.stress}, {"err", p.err}, {"seed_scatter", p.seed_scatter},
                      {"within_err", p.within_err}, {"seeds", p.seeds}, {"stress_fluid", p.stress_fluid},
                      {"eta_r", er.back()}, {"eta_r_err", ee.back()}});
    }
    const auto bingham = mrf::fit_bingham(mn, er, ee);
    const auto power = mrf::fit_power_law(mn, er, ee);
    out["models"][model] = {{"points", rows}, {"bingham", fit_json(bingham)}, {"power_law", fit_json(power)}};
    std::printf("%-14s Bingham: eta_inf = %.3g +- %.2g, Mn* = %.3g +- %.2g (chi2/dof %.2g)%s\n", model.c_str(),
                bingham.eta_inf, bingham.eta_inf_err, bingham.mason_star, bingham.mason_star_err, bingham.chi2_dof,
                bingham.ok ? "" : (" [" + bingham.message + "]").c_str());
    std::printf("%-14s power law: eta_inf = %.3g +- %.2g, Mn* = %.3g +- %.2g, Delta = %.3f +- %.3f (chi2/dof %.2g)%s\n",
                "", power.eta_inf, power.eta_inf_err, power.mason_star, power.mason_star_err, power.exponent,
                power.exponent_err, power.chi2_dof, power.ok ? "" : (" [" + power.message + "]").c_str());
  }
  const bool have_ref = curves.count("demsph_dd") > 0;
  for (const char* m : {"dem_stokes", "demsph_stokes"}) {
    if (!have_ref || !curves.count(m)) continue;
    const auto dev = mrf::deviation(curves[m], curves["demsph_dd"]);
    ordered_json rows = ordered_json::array();
    int hits = 0, tested = 0;
    for (const auto& d : dev) {
      ordered_json r{{"mason", d.mason},    {"deviation", d.value},
                     {"err", d.err},        {"share", d.share},
                     {"mismatch", d.mismatch}, {"volume_deviation", d.volume_value},
                     {"stokes", d.stokes},  {"reynolds", d.reynolds}};
      if (std::string(m) == "dem_stokes")
        for (double level : {0.1, 0.2}) {  // the self-consistency verdict against the actual deviation
          const bool predicted = mrf::consistency_adequate(d.mismatch, d.reynolds, level);
          const bool actual = std::abs(d.value) < level;
          r[level == 0.1 ? "consistency_hit_10" : "consistency_hit_20"] = predicted == actual;
          hits += predicted == actual;
          ++tested;
        }
      rows.push_back(r);
      std::printf("%-14s Mn = %-6.3g tau/tau_3 - 1 = %+.3f +- %.3f, share s = %.3f, mismatch m = %+.3f, St = %.2g, "
                  "Re_p = %.2g, volume stress/tau_3 - 1 = %+.3f\n",
                  m, d.mason, d.value, d.err, d.share, d.mismatch, d.stokes, d.reynolds, d.volume_value);
    }
    out["deviation_from_demsph_dd"][m]["points"] = rows;
    if (tested) {
      out["deviation_from_demsph_dd"][m]["consistency_hit_rate"] = static_cast<double>(hits) / tested;
      std::printf("%-14s self-consistency criterion (|m| < level and Re_p < %.2g <=> |tau_1/tau_3 - 1| < level): %d "
                  "of %d verdicts right\n", m, mrf::k_criterion_max_reynolds, hits, tested);
    }
    for (double level : {0.1, 0.2}) {
      const auto c = mrf::first_crossing(dev, level);
      const std::string key = level == 0.1 ? "crossing_10" : "crossing_20";
      out["deviation_from_demsph_dd"][m][key] = {
          {"found", c.found}, {"below_range", c.below_range}, {"mason", c.mason}, {"share", c.share}};
      if (c.below_range)
        std::printf("%-14s departs from demsph_dd by more than %2.0f %% already at the lowest Mn = %.3g\n", m,
                    100 * level, c.mason);
      else if (c.found)
        std::printf("%-14s departs from demsph_dd by %2.0f %% at Mn = %.3g (hydrodynamic share s = %.3g)\n", m,
                    100 * level, c.mason, c.share);
      else
        std::printf("%-14s stays within %2.0f %% of demsph_dd over the sweep\n", m, 100 * level);
    }
  }
  if (have_ref && curves.count("dem_stokes")) {
    const auto& d = out["deviation_from_demsph_dd"]["dem_stokes"];
    if (d["crossing_10"]["found"] && d["crossing_20"]["found"] && !d["crossing_10"]["below_range"] &&
        !d["crossing_20"]["below_range"])
      out["derived_thresholds"] = {{"share_10", d["crossing_10"]["share"]}, {"share_20", d["crossing_20"]["share"]},
                                   {"mason_10", d["crossing_10"]["mason"]}, {"mason_20", d["crossing_20"]["mason"]}};
  }
  out["preregistered_criterion"] = preregistered_json(mrf::score_criterion(curves));
  if (t && curves.count("dem_stokes")) {
    // verdict per model-1 point, and where model 3 was run too, the hit rate
    int hits = 0, tested = 0;
    const auto pts = curves["dem_stokes"];
    std::vector<mrf::Deviation> dev;
    if (have_ref) dev = mrf::deviation(pts, curves["demsph_dd"]);
    ordered_json rows = ordered_json::array();
    for (const auto& p : pts) {
      const double share = p.stress_fluid / p.stress;
      const auto v = mrf::apply_criterion(share, t->s10, t->s20);
      ordered_json r{{"mason", p.mason}, {"share", share}, {"adequate_10", v.adequate_10}, {"adequate_20", v.adequate_20}};
      for (const auto& d : dev)
        if (d.mason == p.mason) {
          const bool ok10 = std::abs(d.value) < 0.1, ok20 = std::abs(d.value) < 0.2;
          r["deviation"] = d.value;
          r["hit_10"] = ok10 == v.adequate_10;
          r["hit_20"] = ok20 == v.adequate_20;
          hits += (ok10 == v.adequate_10) + (ok20 == v.adequate_20);
          tested += 2;
        }
      rows.push_back(r);
      char what[64];
      std::snprintf(what, sizeof what, "Mn = %.3g", p.mason);
      print_verdict(what, share, *t);
    }
    out["verdicts"] = {{"thresholds", t->source}, {"share_10", t->s10}, {"share_20", t->s20}, {"points", rows}};
    if (tested) {
      out["verdicts"]["hit_rate"] = static_cast<double>(hits) / tested;
      std::printf("criterion hit rate on this sweep: %d of %d verdicts (10 %% and 20 %%) agree with model 3\n", hits,
                  tested);
    }
  }
  mrf::write_file_atomic(path + "/criterion.json", out.dump(2) + "\n");
  std::printf("-> %s/criterion.json\n", path.c_str());
  return 0;
}
