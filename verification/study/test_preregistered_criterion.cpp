// The pre-registered model-1 criterion (issue 14): its drag ratio, its
// shortfall and error on constructed runs, the scoring of verdicts, and its
// domain against the held-out design it is tested on.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "mrf/io/toml_scene.hpp"
#include "mrf/study/criterion.hpp"
#include "mrf/study/sweep.hpp"

namespace mrf {
namespace {

TEST(PreregisteredCriterion, DragRatioIsDiFelicesLowReynoldsLimit) {
  EXPECT_NEAR(difelice_over_stokes(0.0), 0.96, 1e-12);
  for (double phi : {0.05, 0.2, 0.3, 0.35})
    EXPECT_NEAR(difelice_over_stokes(phi), 0.96 * std::pow(1.0 - phi, -2.7), 1e-12) << phi;
}

// delta = 1 - wall / (volume + (g - 1) max(contact, 0)), its error the
// first-order propagation of the three independent errors.
TEST(PreregisteredCriterion, ShortfallOfAConstructedRun) {
  const Model1Stresses s{80, 1, 100, 2, 10, 1, 0.3};
  const Shortfall r = predicted_shortfall(s);
  const double g = 0.96 * std::pow(0.7, -2.7);
  EXPECT_NEAR(r.drag_ratio, g, 1e-12);
  EXPECT_NEAR(r.mismatch, 0.2, 1e-15);
  EXPECT_NEAR(r.mismatch_err, 0.8 * std::hypot(1.0 / 80, 2.0 / 100), 1e-15);
  EXPECT_NEAR(r.reference, 100 + (g - 1) * 10, 1e-12);
  EXPECT_NEAR(r.value, 1 - 80 / (100 + (g - 1) * 10), 1e-15);
  // the error by central differences in each input
  const auto delta = [&](double w, double v, double c) {
    return predicted_shortfall({w, 0, v, 0, c, 0, 0.3}).value;
  };
  const double h = 1e-4;
  const double dw = (delta(80 + h, 100, 10) - delta(80 - h, 100, 10)) / (2 * h);
  const double dv = (delta(80, 100 + h, 10) - delta(80, 100 - h, 10)) / (2 * h);
  const double dc = (delta(80, 100, 10 + h) - delta(80, 100, 10 - h)) / (2 * h);
  EXPECT_NEAR(r.err, std::sqrt(dw * dw * 1 + dv * dv * 4 + dc * dc * 1), 1e-8);
  // a negative contact virial is not drag-set: the reference is the volume side
  const Shortfall neg = predicted_shortfall({80, 1, 100, 2, -5, 1, 0.3});
  EXPECT_DOUBLE_EQ(neg.reference, 100);
  EXPECT_NEAR(neg.value, neg.mismatch, 1e-15);
  // a dilute suspension: g - 1 < 0 lowers the reference (Di Felice's 0.96 at phi -> 0)
  EXPECT_LT(predicted_shortfall({80, 1, 100, 2, 10, 1, 0.01}).reference, 100);
}

TEST(PreregisteredCriterion, VerdictUsesTheMagnitudeOfTheShortfall) {
  Shortfall s;
  s.value = -0.05;
  EXPECT_TRUE(shortfall_adequate(s, 0.1));
  s.value = 0.05;
  EXPECT_TRUE(shortfall_adequate(s, 0.1));
  s.value = 0.15;
  EXPECT_FALSE(shortfall_adequate(s, 0.1));
  EXPECT_TRUE(shortfall_adequate(s, 0.2));
}

TEST(PreregisteredCriterion, ScoresRightWrongAndUndecidable) {
  EXPECT_EQ(score_verdict(true, -0.05, 0.01, 0.1), Outcome::right_adequate);
  EXPECT_EQ(score_verdict(true, 0.05, 0.01, 0.1), Outcome::right_adequate);  // model 1 high by 5 %: within too
  EXPECT_EQ(score_verdict(true, -0.15, 0.01, 0.1), Outcome::wrong_adequate);
  EXPECT_EQ(score_verdict(false, -0.05, 0.01, 0.1), Outcome::wrong_not_adequate);
  EXPECT_EQ(score_verdict(false, -0.15, 0.01, 0.1), Outcome::right_not_adequate);
  EXPECT_EQ(score_verdict(false, -0.095, 0.01, 0.1), Outcome::undecidable);
  EXPECT_EQ(score_verdict(true, -0.105, 0.01, 0.1), Outcome::undecidable);
  EXPECT_EQ(score_verdict(true, -0.115, 0.01, 0.1), Outcome::wrong_adequate);
  Confusion c;
  EXPECT_TRUE(std::isnan(c.right_fraction()));
  EXPECT_TRUE(std::isnan(c.adequate_right_fraction()));
  for (Outcome o : {Outcome::right_adequate, Outcome::right_adequate, Outcome::right_adequate, Outcome::wrong_adequate,
                    Outcome::right_not_adequate, Outcome::wrong_not_adequate, Outcome::undecidable})
    c.add(o);
  EXPECT_EQ(c.decidable(), 6);
  EXPECT_EQ(c.undecidable, 1);
  EXPECT_DOUBLE_EQ(c.right_fraction(), 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(c.adequate_right_fraction(), 3.0 / 4.0);
}

TEST(PreregisteredCriterion, OutsideTheDomainNamesEachCondition) {
  EXPECT_TRUE(outside_domain({0.2, 50, 0.3, 1e-3, 1e-3}).empty());
  EXPECT_TRUE(outside_domain({0.2, 0, 0.3, 1e-3, 1e-3}).empty());  // gap/R unknown (an older summary.json)
  const auto w = outside_domain({0.4, 50, 0.3, 0.1, 1e-3});
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0], "phi = 0.4 > 0.33");
  EXPECT_EQ(w[1], "St = 0.1 > 0.03");
  EXPECT_EQ(outside_domain({0.2, 10, 0.001, 0, 0}).size(), 2u);  // gap/R and Mn below
  // the gap Reynolds number Re_p (gap/R)^2: 4e-3 * 50^2 = 10 is the edge, 20 is beyond it
  EXPECT_DOUBLE_EQ(gap_reynolds({0.2, 50, 0.3, 1e-3, 4e-3}), 10.0);
  EXPECT_TRUE(outside_domain({0.2, 50, 0.3, 1e-3, 3.9e-3}).empty());
  const auto r = outside_domain({0.2, 50, 0.3, 1e-3, 8e-3});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], "Re_gap = 20 > 10");
}

FlowPoint point(double mason, double stress, double volume, double contact, double phi) {
  FlowPoint p;
  p.mason = mason;
  p.stress = stress;
  p.err = 1;
  p.stress_volume = volume;
  p.volume_err = 1;
  p.stress_contact = contact;
  p.contact_err = 0.1;
  p.volume_fraction = phi;
  p.gap_over_radius = 50;
  p.seeds = 2;
  return p;
}

// Each model-1 curve is scored against the model-3 curve of its own variant
// only; a model-1 point without its volume side, or without a model-3 partner,
// is left out; a point outside the domain counts in the scores of every point
// but not in those inside the domain.
TEST(PreregisteredCriterion, ScoresEachVariantAgainstItsOwnModel3) {
  FlowPoint inertial = point(1, 90, 95, 2, 0.1);
  inertial.reynolds = 0.01;  // Re_gap = 0.01 * 50^2 = 25 > 10
  const std::map<std::string, std::vector<FlowPoint>> curves{
      {"dem_stokes@a", {point(1, 90, 95, 2, 0.1)}},   // delta = 0.058: adequate
      {"demsph_dd@a", {point(1, 97, 97, 0, 0.1)}},    // D = -0.072: right at both levels
      {"dem_dd@a", {point(1, 93, 96, 2, 0.1)}},       // delta_dd = 1 - 90/96 = 0.0625: adequate at both
      {"dem_dd@b", {point(1, 61, 70, 2, 0.1)}},       // delta_dd = 1 - 60/70 = 0.143: adequate at 20 % only
      {"dem_stokes@b", {point(1, 60, 95, 2, 0.1)}},   // delta = 0.37: not adequate
      {"demsph_dd@b", {point(1, 64, 64, 0, 0.1)}},    // D = -0.0625: the conservative error at both
      {"dem_stokes@c", {point(1, 60, 95, 2, 0.1)}},   // no demsph_dd@c
      {"dem_stokes@d", {point(1, 60, 0, 0, 0.1)}},    // no volume side
      {"demsph_dd@d", {point(1, 64, 64, 0, 0.1)}},
      {"dem_stokes@e", {inertial}},                   // adequate, outside the domain
      {"demsph_dd@e", {point(1, 110, 110, 0, 0.1)}}};  // D = -0.18: wrong at 10 %, right at 20 %
  const CriterionScore sc = score_criterion(curves);
  ASSERT_EQ(sc.points.size(), 3u);
  EXPECT_EQ(sc.points[2].outside, (std::vector<std::string>{"Re_gap = 25 > 10"}));
  // the one-way Di Felice estimate: model 1's wall stress over dem_dd's volume side
  ASSERT_TRUE(sc.points[0].has_dd && sc.points[1].has_dd);
  EXPECT_FALSE(sc.points[2].has_dd);
  EXPECT_NEAR(sc.points[0].dd.value, 1 - 90.0 / 96, 1e-15);
  EXPECT_NEAR(sc.points[0].dd.err, 90.0 / 96 * std::hypot(1.0 / 90, 1.0 / 96), 1e-15);
  EXPECT_NEAR(sc.points[1].dd.value, 1 - 60.0 / 70, 1e-15);
  EXPECT_EQ(sc.one_way_dd[0].right_adequate, 1);
  EXPECT_EQ(sc.one_way_dd[0].wrong_not_adequate, 1);  // D = -0.0625 at b
  EXPECT_EQ(sc.one_way_dd[1].right_adequate, 2);
  EXPECT_EQ(sc.one_way_dd[1].decidable(), 2);
  EXPECT_EQ(sc.rule[0].wrong_adequate, 1);
  EXPECT_EQ(sc.rule[1].right_adequate, 2);
  EXPECT_EQ(sc.points[0].curve, "dem_stokes@a");
  EXPECT_NEAR(sc.points[0].deviation, 90.0 / 97 - 1, 1e-15);
  EXPECT_NEAR(sc.points[0].shortfall.value, 1 - 90 / (95 + 2 * (difelice_over_stokes(0.1) - 1)), 1e-15);
  EXPECT_NEAR(sc.points[1].deviation, 60.0 / 64 - 1, 1e-15);
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(sc.points[0].adequate[k]);
    EXPECT_FALSE(sc.points[1].adequate[k]);
    EXPECT_EQ(sc.rule[k].wrong_not_adequate, 1);
    EXPECT_EQ(sc.rule[k].decidable(), 3);
    EXPECT_EQ(sc.rule_in_domain[k].right_adequate, 1);
    EXPECT_EQ(sc.rule_in_domain[k].wrong_adequate, 0);
    EXPECT_EQ(sc.rule_in_domain[k].wrong_not_adequate, 1);
    EXPECT_EQ(sc.rule_in_domain[k].decidable(), 2);
    EXPECT_EQ(sc.mismatch_only[k].right_adequate, k == 0 ? 1 : 2);  // m = 0.053 and 0.37 give the rule's verdicts here
    EXPECT_EQ(sc.mismatch_only[k].wrong_not_adequate, 1);
  }
}

// The domain the verdict states is the one the held-out designs span.
// Each design point's conditions, as the scene builder sees them (seed 1, model 1).
std::vector<std::pair<std::string, RunConditions>> design_conditions(const SweepSpec& spec) {
  std::vector<std::pair<std::string, RunConditions>> out;
  for (const SweepPoint& p : sweep_points(spec)) {
    if (p.model != "dem_stokes" || p.seed != spec.seeds.front()) continue;
    const SceneConfig c = load_scene(spec.scene_path, p.sets).config;
    const double st = 2 * c.density * c.radius * c.radius / (9 * c.viscosity) * c.shear_rate;
    const double re = c.fluid_density * c.shear_rate * c.radius * c.radius / c.viscosity;
    out.emplace_back(p.dir, RunConditions{c.volume_fraction, c.gap / c.radius, p.mason, st, re});
  }
  return out;
}

// Design 2 lies inside the revised domain and reaches its edges.
TEST(PreregisteredCriterion, DomainEnclosesTheSecondHeldOutDesign) {
  const SweepSpec spec = load_sweep(MRF_SOURCE_DIR "/experiments/sweeps/criterion_heldout2.toml");
  EXPECT_GE(spec.variants.size(), 24u);
  EXPECT_GE(spec.seeds.size(), 2u);
  EXPECT_EQ(spec.models, (std::vector<std::string>{"dem_stokes", "demsph_dd", "dem_dd"}));
  double phi_lo = 1, phi_hi = 0, gr_lo = 1e9, gr_hi = 0, re_hi = 0;
  std::set<double> mason;
  for (const auto& [dir, rc] : design_conditions(spec)) {
    const auto w = outside_domain(rc);
    EXPECT_TRUE(w.empty()) << dir << ": " << (w.empty() ? "" : w.front());
    phi_lo = std::min(phi_lo, rc.volume_fraction);
    phi_hi = std::max(phi_hi, rc.volume_fraction);
    gr_lo = std::min(gr_lo, rc.gap_over_radius);
    gr_hi = std::max(gr_hi, rc.gap_over_radius);
    re_hi = std::max(re_hi, gap_reynolds(rc));
    mason.insert(rc.mason);
  }
  const CriterionDomain d;
  EXPECT_LT(phi_lo, d.phi_min + 0.02);
  EXPECT_GT(phi_hi, d.phi_max - 0.01);
  EXPECT_LT(gr_lo, 1.2 * d.gap_over_radius_min);
  EXPECT_GT(gr_hi, 0.9 * d.gap_over_radius_max);
  EXPECT_GT(re_hi, 0.9 * d.gap_reynolds_max);
  EXPECT_EQ(*mason.begin(), d.mason_min);
  EXPECT_EQ(*mason.rbegin(), d.mason_max);
}

// Design 1 was drawn inside the domain as pre-registered (without the gap
// Reynolds bound): its points leave the revised domain on Re_gap alone.
TEST(PreregisteredCriterion, FirstDesignLeavesTheRevisedDomainOnlyByItsGapReynoldsNumber) {
  const SweepSpec spec = load_sweep(MRF_SOURCE_DIR "/experiments/sweeps/criterion_heldout.toml");
  EXPECT_GE(spec.variants.size(), 24u);
  int beyond = 0;
  for (const auto& [dir, rc] : design_conditions(spec)) {
    const auto w = outside_domain(rc);
    EXPECT_EQ(w.empty(), gap_reynolds(rc) <= CriterionDomain{}.gap_reynolds_max) << dir;
    if (!w.empty()) {
      EXPECT_EQ(w.size(), 1u) << dir << ": " << w.front();
      EXPECT_EQ(w.front().rfind("Re_gap", 0), 0u) << dir << ": " << w.front();
      ++beyond;
    }
  }
  EXPECT_GT(beyond, 0);
}

}  // namespace
}  // namespace mrf
