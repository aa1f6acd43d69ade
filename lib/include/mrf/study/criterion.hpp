// The applicability criterion of model 1 (issue 6): where the one-way
// DEM-Stokes stress departs from the two-way DEM-SPH-DD stress, expressed
// through numbers a modeller can read off a single model-1 run:
//  - the hydrodynamic share s = tau_fluid / tau_total (= eta gdot / tau for
//    the imposed Couette flow): model 1 adequate at accuracy a where s < s_a,
//    s_a the share at which |tau_1/tau_3 - 1| first reaches a (log-interpolated
//    in Mn); undefined when the first sweep point already misses a;
//  - the self-consistency mismatch m = 1 - tau_wall / tau_volume of the run
//    (wall stress against pair virial + eta gdot): the imposed fluid of model 1
//    absorbs the stress of clusters that do not reach a wall, which the
//    two-way models return to the walls; model 1 adequate at a where |m| < a
//    and the particle Reynolds number Re_p = rho_f gdot R^2 / eta < 0.05
//    (beyond, the two-way fluid's stress exceeds eta gdot, which model 1's
//    imposed Stokes profile cannot show). History, because both clauses were
//    chosen after seeing data: a Stokes-number clause (St < 0.1) was added
//    after the held-out phi = 0.10 sweep showed model 1 off by 18-47 % at
//    Mn >= 1 with |m| <= 0.1; the next held-out sweep, with 10x lighter
//    particles, refuted it (off by 19-39 % at St 0.03-0.09), while the
//    deviation followed the fluid's Reynolds number. The Re clause has not yet
//    been tested on data not used to choose it.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "mrf/study/flow_curve.hpp"

namespace mrf {

// sweep.csv rows with status ok, grouped by model (carrier viscosity and
// density taken from the rows; all rows of a sweep share them). Each sample
// keeps its own magnetization: a sweep on the realistic path (drive.vary =
// magnetization) reaches each Mn with its own M at one shear rate;
// `magnetization` is the value all rows share, 0 when they differ.
struct SweepTable {
  std::map<std::string, std::vector<StressSample>> samples;  // by model, or "model@variant" in a sweep with variants
  double magnetization = 0, viscosity = 0, fluid_density = 0, volume_fraction = 0;  // A/m, Pa s, kg/m^3, 1
  std::string viscosity_note;  // how the viscosity was found when sweep.csv has no viscosity value
};
// The viscosity comes from the `viscosity` column (summary.json's since it
// carries the fluid viscosity). A sweep.csv of an earlier mrf has none: then
// eta = stress_fluid / shear_rate of the first ok dem_stokes row (model 1's
// imposed flow carries exactly eta gdot), with viscosity_note saying so; an
// InputError when such a sweep has rows but no dem_stokes row to infer it
// from. fluid_density is 0 when sweep.csv has no such column.
SweepTable read_sweep_csv(const std::string& path);

struct Deviation {
  double mason = 0;
  double value = 0, err = 0;  // tau_m / tau_ref - 1 and its standard error
  double share = 0;           // hydrodynamic share of model m, tau_fluid / tau_total
  double mismatch = 0;        // 1 - tau_m / tau_volume,m (0 when the volume stress is unknown)
  double volume_value = 0;    // tau_volume,m / tau_ref - 1 (the volume-side estimate of the reference)
  double stokes = 0;          // Stokes number of model m's runs
  double reynolds = 0;        // particle Reynolds number of model m's runs
};

inline constexpr double k_criterion_max_reynolds = 0.05;

// The self-consistency verdict: model 1 within `level` of model 3 when
// |m| < level and Re_p < k_criterion_max_reynolds.
bool consistency_adequate(double mismatch, double reynolds, double level);

// tau_m/tau_ref - 1 at the Mason numbers both flow curves have.
std::vector<Deviation> deviation(const std::vector<FlowPoint>& model, const std::vector<FlowPoint>& ref);

struct Crossing {
  bool found = false;
  bool below_range = false;  // already past the level at the lowest Mn of the sweep
  double mason = 0;  // first Mn (from below) where |deviation| reaches the level, log-interpolated
  double share = 0;  // hydrodynamic share there, interpolated the same way
};
Crossing first_crossing(const std::vector<Deviation>& d, double level);

struct CriterionVerdict {
  double share = 0;
  bool adequate_10 = false, adequate_20 = false;
};
// s_10, s_20: the thresholds derived from a reference sweep.
CriterionVerdict apply_criterion(double share, double s10, double s20);

}  // namespace mrf
