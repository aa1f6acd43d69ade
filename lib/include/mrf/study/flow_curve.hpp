// Flow curves: seed-averaged stress against Mason number, and the fits of
// REFERENCE.md §7 with GSL (weighted least squares, uncertainties from the
// covariance, inflated by chi^2/dof when the scatter exceeds the error bars).
//
// Relative viscosity eta_r = tau / (eta gdot), eta the carrier viscosity,
// gdot = 2 mu0 M^2 Mn / (9 eta) (DESIGN.md convention).
//   Bingham:   eta_r = eta_inf (1 + Mn*/Mn)             (linear in 1/Mn)
//   power law: eta_r = eta_inf (1 + (Mn*/Mn)^Delta)     (Delta free, nonlinear)
// Delta = 1 is Bingham; Casson-like and chain-model curves have Delta < 1.
// In stress units the Bingham yield stress is tau_y = (2/9) eta_inf Mn* mu0 M^2.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace mrf {

// One run's measurement.
struct StressSample {
  double mason = 0;
  std::uint64_t seed = 0;
  double stress = 0, err = 0;  // Pa, standard error within the run
  double stress_fluid = 0;     // Pa, the hydrodynamic part (eta gdot for model 1)
  double stress_volume = 0;    // Pa, volume-side total: pair virial + fluid (stress_virial_total)
  double volume_err = 0;       // Pa, its standard error within the run
  double stress_contact = 0;   // Pa, the contact part of the pair virial (stress_virial_contact)
  double contact_err = 0;      // Pa, its standard error within the run
  double stokes = 0;           // Stokes number tau_p gdot of the run
  double reynolds = 0;         // particle Reynolds number rho_f gdot R^2 / eta of the run
  double magnetization = 0;    // A/m: the run's own (it varies with Mn on the path drive.vary = magnetization)
  double volume_fraction = 0;  // 1
  double gap_over_radius = 0;  // 1 (0 when sweep.csv has no gap and radius)
};

// Seed average at one Mason number.
struct FlowPoint {
  double mason = 0;
  double stress = 0;        // mean over seeds (Pa)
  double err = 0;           // standard error of that mean: the larger of the seed scatter/sqrt(n) and the within-run errors combined
  double seed_scatter = 0;  // sample standard deviation between seeds (Pa); 0 for one seed
  double within_err = 0;    // sqrt(sum err_i^2)/n (Pa)
  double stress_fluid = 0;  // mean hydrodynamic part (Pa)
  double stress_volume = 0; // mean volume-side total (Pa)
  double volume_err = 0;    // its standard error, as err is the wall stress's
  double stress_contact = 0;// mean contact part of the pair virial (Pa)
  double contact_err = 0;   // its standard error, likewise
  double stokes = 0;        // Stokes number (the same for every seed)
  double reynolds = 0;      // particle Reynolds number (the same for every seed)
  double magnetization = 0; // A/m (the same for every seed)
  double volume_fraction = 0, gap_over_radius = 0;  // likewise
  int seeds = 0;
};

// Groups samples by Mason number (exact equality), sorted by Mn.
std::vector<FlowPoint> seed_average(const std::vector<StressSample>& samples);

struct FlowFit {
  double eta_inf = 0, eta_inf_err = 0;      // relative high-shear viscosity (1)
  double mason_star = 0, mason_star_err = 0;
  double exponent = 1, exponent_err = 0;    // Delta; fixed at 1 (err 0) for Bingham
  // Bingham: b of eta_r = eta_inf + b / Mn (= eta_inf Mn*), with its error
  // (covariance inflated as the others); tau_y / (phi mu0 M^2) = b / (4.5 phi)
  double slope = 0, slope_err = 0;
  double chi2_dof = 0;
  int dof = 0;
  bool ok = false;
  std::string message;  // why not ok
};

// Relative viscosity of a point and its error: tau/(eta gdot).
double relative_viscosity(double stress, double mason, double viscosity, double magnetization);

// Fits to points (Mn, eta_r, err_r); at least 3 points (4 for the power law).
FlowFit fit_bingham(const std::vector<double>& mason, const std::vector<double>& eta_r,
                    const std::vector<double>& err_r);
FlowFit fit_power_law(const std::vector<double>& mason, const std::vector<double>& eta_r,
                      const std::vector<double>& err_r);

double flow_curve_eta_r(const FlowFit& f, double mason);  // eta_inf (1 + (Mn*/Mn)^Delta)

}  // namespace mrf
