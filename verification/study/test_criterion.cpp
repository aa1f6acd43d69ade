// The model-1 applicability criterion on constructed flow curves with a known
// deviation, and the sweep.csv reader.
#include "mrf/study/criterion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mrf/error.hpp"

namespace mrf {
namespace {

// Model 3 = model 1 with its hydrodynamic part scaled by k: tau3 = tau_mag + k eta gdot,
// so tau1/tau3 - 1 = (1 - k) s / (1 + (k - 1) s) with s the share of model 1.
std::vector<FlowPoint> curve(double k) {
  std::vector<FlowPoint> out;
  for (double lm = -4; lm <= 0.01; lm += 1) {
    const double mn = std::pow(10.0, lm), fluid = 1e4 * mn, mag = 1e3 * std::pow(mn, 0.2);
    FlowPoint p;
    p.mason = mn;
    p.stress = mag + k * fluid;
    p.stress_fluid = k * fluid;
    p.err = 0.01 * p.stress;
    out.push_back(p);
  }
  return out;
}

TEST(Criterion, DeviationAndShareFollowTheConstruction) {
  const auto m1 = curve(1.0), m3 = curve(2.5);
  const auto d = deviation(m1, m3);
  ASSERT_EQ(d.size(), 5u);
  for (const auto& x : d) {
    const double s = x.share;
    EXPECT_NEAR(x.value, -1.5 * s / (1 + 1.5 * s), 1e-12);
    EXPECT_NEAR(x.err, (1 + x.value) * 0.01 * std::sqrt(2.0), 1e-12);
  }
  EXPECT_LT(d.front().share, 0.01);
  EXPECT_GT(d.back().share, 0.9);
}

TEST(Criterion, CrossingIsInterpolatedInLogMason) {
  std::vector<Deviation> d{{1e-3, -0.05, 0, 0.1}, {1e-2, -0.15, 0, 0.3}, {1e-1, -0.5, 0, 0.8}};
  const Crossing c10 = first_crossing(d, 0.1);
  ASSERT_TRUE(c10.found);
  EXPECT_NEAR(c10.mason, std::sqrt(1e-3 * 1e-2), 1e-15);  // halfway in log Mn
  EXPECT_NEAR(c10.share, 0.2, 1e-12);
  const Crossing c20 = first_crossing(d, 0.2);
  EXPECT_NEAR(std::log10(c20.mason), -2 + 0.05 / 0.35, 1e-12);
  EXPECT_FALSE(first_crossing(d, 0.6).found);
  const Crossing below = first_crossing(d, 0.01);  // above the level at the first point
  EXPECT_TRUE(below.found);
  EXPECT_EQ(below.mason, 1e-3);
  EXPECT_TRUE(apply_criterion(0.19, 0.2, 0.4).adequate_10);
  EXPECT_FALSE(apply_criterion(0.21, 0.2, 0.4).adequate_10);
  EXPECT_TRUE(apply_criterion(0.21, 0.2, 0.4).adequate_20);
}

TEST(Criterion, ConsistencyVerdictNeedsSmallMismatchAndSmallReynolds) {
  EXPECT_TRUE(consistency_adequate(0.05, 0.01, 0.1));
  EXPECT_TRUE(consistency_adequate(-0.05, 0.01, 0.1));
  EXPECT_FALSE(consistency_adequate(0.15, 0.01, 0.1));
  EXPECT_TRUE(consistency_adequate(0.15, 0.01, 0.2));
  EXPECT_FALSE(consistency_adequate(0.05, 0.2, 0.1));  // fluid inertia: the two-way fluid stress differs
}

TEST(Criterion, ReadsSweepCsvSkippingFailedPoints) {
  const auto p = std::filesystem::temp_directory_path() / "mrf_test_sweep.csv";
  std::ofstream(p) << "model,mason,seed,status,shear_rate,stress_total,stress_total_err,stress_fluid,"
                      "stress_virial_total,stokes_number,reynolds_number,magnetization,volume_fraction,dir\n"
                      "dem_stokes,0.01,1,ok,100,50,1,10,80,0.003,0.002,1000000,0.3,a\n"
                      "dem_stokes,0.01,2,failed,,,,,,,,,,b\n"
                      "demsph_dd,0.01,1,ok,100,60,2,20,60,0.003,0.002,1000000,0.3,c\n";
  const SweepTable t = read_sweep_csv(p.string());
  ASSERT_EQ(t.samples.at("dem_stokes").size(), 1u);
  ASSERT_EQ(t.samples.at("demsph_dd").size(), 1u);
  EXPECT_DOUBLE_EQ(t.viscosity, 0.1);  // no viscosity column: inferred from the dem_stokes row, and said so
  EXPECT_NE(t.viscosity_note.find("stress_fluid/shear_rate"), std::string::npos) << t.viscosity_note;
  EXPECT_DOUBLE_EQ(t.magnetization, 1e6);
  EXPECT_DOUBLE_EQ(seed_average(t.samples.at("dem_stokes"))[0].magnetization, 1e6);
  EXPECT_DOUBLE_EQ(t.samples.at("demsph_dd")[0].stress_fluid, 20);
  EXPECT_DOUBLE_EQ(t.samples.at("dem_stokes")[0].stress_volume, 80);
  EXPECT_DOUBLE_EQ(t.samples.at("dem_stokes")[0].stokes, 0.003);
  EXPECT_DOUBLE_EQ(t.samples.at("dem_stokes")[0].reynolds, 0.002);
  const auto d = deviation(seed_average(t.samples.at("dem_stokes")), seed_average(t.samples.at("demsph_dd")));
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].mismatch, 1.0 - 50.0 / 80.0, 1e-15);
  EXPECT_NEAR(d[0].volume_value, 80.0 / 60.0 - 1.0, 1e-15);
}

// sweep.csv carries the carrier viscosity and density (from summary.json):
// a sweep without a model-1 row has them too.
TEST(Criterion, ReadsViscosityAndFluidDensityWithoutAModel1Row) {
  const auto p = std::filesystem::temp_directory_path() / "mrf_test_sweep_eta.csv";
  std::ofstream(p) << "model,mason,seed,status,shear_rate,stress_total,stress_total_err,stress_fluid,"
                      "magnetization,volume_fraction,viscosity,fluid_density,dir\n"
                      "demsph_dd,0.01,1,ok,100,60,2,20,1000000,0.3,0.25,960,c\n"
                      "demsph_dd,0.1,1,ok,1000,90,2,30,1000000,0.3,0.25,960,d\n";
  const SweepTable t = read_sweep_csv(p.string());
  EXPECT_DOUBLE_EQ(t.viscosity, 0.25);
  EXPECT_DOUBLE_EQ(t.fluid_density, 960);
  EXPECT_TRUE(t.viscosity_note.empty()) << t.viscosity_note;
  EXPECT_TRUE(std::isfinite(relative_viscosity(60, 0.01, t.viscosity, t.magnetization)));
}

// An older sweep.csv (no viscosity column) without a dem_stokes row: a clear
// error naming the file, not eta = 0 and a 0/0 in the relative viscosity.
TEST(Criterion, OldSweepCsvWithoutViscosityOrModel1RowIsAClearError) {
  const auto p = std::filesystem::temp_directory_path() / "mrf_test_sweep_old.csv";
  std::ofstream(p) << "model,mason,seed,status,shear_rate,stress_total,stress_total_err,stress_fluid,"
                      "magnetization,volume_fraction,dir\n"
                      "dem_stokes,0.01,1,failed,,,,,,,a\n"
                      "demsph_dd,0.01,1,ok,100,60,2,20,1000000,0.3,c\n";
  try {
    const SweepTable t = read_sweep_csv(p.string());
    FAIL() << "no error; viscosity = " << t.viscosity;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("viscosity"), std::string::npos) << msg;
    EXPECT_NE(msg.find("dem_stokes"), std::string::npos) << msg;
  }
}

// The realistic path (drive.vary = magnetization): one shear rate, each Mn
// reached by its own M. Every sample and flow point keeps its own M, so the
// relative viscosity is tau / (eta gdot) with the sweep's one gdot; the
// table's single magnetization is 0 (it differs between rows).
TEST(Criterion, RealisticPathKeepsEachPointsMagnetization) {
  const auto p = std::filesystem::temp_directory_path() / "mrf_test_sweep_realistic.csv";
  const double eta = 0.1, gdot = 1e3, mu0 = 4e-7 * 3.14159265358979323846;
  auto m_of = [&](double mn) { return std::sqrt(9 * eta * gdot / (2 * mu0 * mn)); };
  std::ofstream out(p);
  out.precision(17);
  out << "model,mason,seed,status,shear_rate,stress_total,stress_total_err,stress_fluid,magnetization,"
         "volume_fraction,viscosity,dir\n";
  out << "dem_stokes,0.001,1,ok,1000,900,9,100," << m_of(1e-3) << ",0.3,0.1,a\n";
  out << "dem_stokes,0.001,2,ok,1000,880,9,100," << m_of(1e-3) << ",0.3,0.1,b\n";
  out << "dem_stokes,0.1,1,ok,1000,115,0.2,100," << m_of(0.1) << ",0.3,0.1,c\n";
  out.close();
  const SweepTable t = read_sweep_csv(p.string());
  EXPECT_EQ(t.magnetization, 0.0);
  const auto pts = seed_average(t.samples.at("dem_stokes"));
  ASSERT_EQ(pts.size(), 2u);
  for (const auto& q : pts) {
    EXPECT_NEAR(q.magnetization, m_of(q.mason), 1e-9 * m_of(q.mason));
    // with the point's own M the relative viscosity is tau / (eta gdot), gdot = 1000 1/s at both Mn
    EXPECT_NEAR(relative_viscosity(q.stress, q.mason, eta, q.magnetization), q.stress / (eta * gdot),
                1e-12 * q.stress / (eta * gdot));
  }
  // the one-M reading (the first row's M for every point) would be off by the ratio of the Mn: 100x here
  EXPECT_NEAR(relative_viscosity(pts[1].stress, pts[1].mason, eta, pts[0].magnetization) /
                  (pts[1].stress / (eta * gdot)), 1e-3 / 0.1, 1e-12);
}

}  // namespace
}  // namespace mrf
