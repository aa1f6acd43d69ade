#include "mrf/study/flow_curve.hpp"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_fit.h>
#include <gsl/gsl_multifit_nlinear.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "mrf/vec.hpp"

namespace mrf {

std::vector<FlowPoint> seed_average(const std::vector<StressSample>& samples) {
  std::map<double, std::vector<const StressSample*>> by_mn;
  for (const auto& s : samples) by_mn[s.mason].push_back(&s);
  std::vector<FlowPoint> out;
  for (const auto& [mn, group] : by_mn) {
    FlowPoint p;
    p.mason = mn;
    p.seeds = static_cast<int>(group.size());
    const double n = static_cast<double>(group.size());
    // mean of one quantity over the seeds, its error the larger of the seed
    // scatter / sqrt(n) and the within-run errors combined
    const auto combine = [&](double StressSample::*value, double StressSample::*err, double& mean, double& scatter,
                             double& within) {
      double sum_err2 = 0;
      mean = 0;
      for (const auto* s : group) {
        mean += s->*value / n;
        sum_err2 += s->*err * (s->*err);
      }
      double ss = 0;
      for (const auto* s : group) ss += (s->*value - mean) * (s->*value - mean);
      scatter = group.size() > 1 ? std::sqrt(ss / (n - 1)) : 0.0;
      within = std::sqrt(sum_err2) / n;
      return std::max(within, scatter / std::sqrt(n));
    };
    for (const auto* s : group) {
      p.stress_fluid += s->stress_fluid / n;
      p.stokes = s->stokes;
      p.reynolds = s->reynolds;
      p.magnetization = s->magnetization;
      p.volume_fraction = s->volume_fraction;
      p.gap_over_radius = s->gap_over_radius;
    }
    p.err = combine(&StressSample::stress, &StressSample::err, p.stress, p.seed_scatter, p.within_err);
    double scatter = 0, within = 0;
    p.volume_err = combine(&StressSample::stress_volume, &StressSample::volume_err, p.stress_volume, scatter, within);
    p.contact_err = combine(&StressSample::stress_contact, &StressSample::contact_err, p.stress_contact, scatter, within);
    out.push_back(p);
  }
  return out;
}

double relative_viscosity(double stress, double mason, double viscosity, double magnetization) {
  const double gdot = 2.0 * k_mu0 * magnetization * magnetization * mason / (9.0 * viscosity);
  return stress / (viscosity * gdot);
}

double flow_curve_eta_r(const FlowFit& f, double mason) {
  return f.eta_inf * (1.0 + std::pow(f.mason_star / mason, f.exponent));
}

FlowFit fit_bingham(const std::vector<double>& mason, const std::vector<double>& eta_r, const std::vector<double>& err_r) {
  FlowFit f;
  const std::size_t n = mason.size();
  if (n < 3 || eta_r.size() != n || err_r.size() != n) {
    f.message = "Bingham fit needs >= 3 points with errors";
    return f;
  }
  std::vector<double> x(n), w(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 1.0 / mason[i];
    w[i] = 1.0 / (err_r[i] * err_r[i]);
  }
  double a, b, c00, c01, c11, chi2;
  gsl_fit_wlinear(x.data(), 1, w.data(), 1, eta_r.data(), 1, n, &a, &b, &c00, &c01, &c11, &chi2);
  f.dof = static_cast<int>(n) - 2;
  f.chi2_dof = chi2 / f.dof;
  const double inflate = std::max(1.0, f.chi2_dof);
  c00 *= inflate;
  c01 *= inflate;
  c11 *= inflate;
  f.eta_inf = a;
  f.eta_inf_err = std::sqrt(c00);
  f.slope = b;
  f.slope_err = std::sqrt(c11);
  f.exponent = 1.0;
  if (a <= 0) {
    f.message = "Bingham fit gives eta_inf <= 0: the data are not Bingham-like";
    return f;
  }
  f.mason_star = b / a;
  f.mason_star_err = std::abs(f.mason_star) * std::sqrt(std::max(0.0, c11 / (b * b) + c00 / (a * a) - 2 * c01 / (a * b)));
  f.ok = b > 0;
  if (!f.ok) f.message = "Bingham fit gives no yield stress (Mn* <= 0)";
  return f;
}

namespace {

struct PowerData {
  const std::vector<double>* mn;
  const std::vector<double>* y;   // ln eta_r
  const std::vector<double>* sy;  // its error
};

// Parameters: a = ln eta_inf, b = ln Mn*, Delta.
int power_f(const gsl_vector* p, void* data, gsl_vector* r) {
  const auto* d = static_cast<const PowerData*>(data);
  const double a = gsl_vector_get(p, 0), b = gsl_vector_get(p, 1), D = gsl_vector_get(p, 2);
  for (std::size_t i = 0; i < d->mn->size(); ++i) {
    const double L = std::log((*d->mn)[i]);
    const double model = a + std::log1p(std::exp(D * (b - L)));
    gsl_vector_set(r, i, (model - (*d->y)[i]) / (*d->sy)[i]);
  }
  return GSL_SUCCESS;
}

int power_df(const gsl_vector* p, void* data, gsl_matrix* J) {
  const auto* d = static_cast<const PowerData*>(data);
  const double b = gsl_vector_get(p, 1), D = gsl_vector_get(p, 2);
  for (std::size_t i = 0; i < d->mn->size(); ++i) {
    const double L = std::log((*d->mn)[i]);
    const double t = std::exp(D * (b - L)), g = t / (1.0 + t), s = (*d->sy)[i];
    gsl_matrix_set(J, i, 0, 1.0 / s);
    gsl_matrix_set(J, i, 1, D * g / s);
    gsl_matrix_set(J, i, 2, (b - L) * g / s);
  }
  return GSL_SUCCESS;
}

}  // namespace

FlowFit fit_power_law(const std::vector<double>& mason, const std::vector<double>& eta_r, const std::vector<double>& err_r) {
  FlowFit f;
  const std::size_t n = mason.size();
  if (n < 4 || eta_r.size() != n || err_r.size() != n) {
    f.message = "power-law fit needs >= 4 points with errors";
    return f;
  }
  std::vector<double> y(n), sy(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(eta_r[i] > 0) || !(err_r[i] > 0)) {
      f.message = "power-law fit needs eta_r > 0 and errors > 0";
      return f;
    }
    y[i] = std::log(eta_r[i]);
    sy[i] = err_r[i] / eta_r[i];
  }
  // Start from the Bingham fit where it makes sense, else from the data's ends.
  const FlowFit bing = fit_bingham(mason, eta_r, err_r);
  const auto lo = std::min_element(eta_r.begin(), eta_r.end());
  double a0 = std::log(*lo * 0.5), b0 = std::log(mason[static_cast<std::size_t>(lo - eta_r.begin())]);
  if (bing.ok) {
    a0 = std::log(bing.eta_inf);
    b0 = std::log(bing.mason_star);
  }
  PowerData data{&mason, &y, &sy};
  gsl_multifit_nlinear_fdf fdf;
  fdf.f = power_f;
  fdf.df = power_df;
  fdf.fvv = nullptr;
  fdf.n = n;
  fdf.p = 3;
  fdf.params = &data;
  gsl_multifit_nlinear_parameters params = gsl_multifit_nlinear_default_parameters();
  gsl_multifit_nlinear_workspace* w = gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &params, n, 3);
  double start[3] = {a0, b0, 1.0};
  gsl_vector_view x0 = gsl_vector_view_array(start, 3);
  gsl_multifit_nlinear_init(&x0.vector, &fdf, w);
  int info = 0;
  const int status = gsl_multifit_nlinear_driver(200, 1e-10, 1e-10, 1e-12, nullptr, nullptr, &info, w);
  gsl_matrix* J = gsl_multifit_nlinear_jac(w);
  gsl_matrix* cov = gsl_matrix_alloc(3, 3);
  gsl_multifit_nlinear_covar(J, 0.0, cov);
  double chi2 = 0;
  gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &chi2);
  f.dof = static_cast<int>(n) - 3;
  f.chi2_dof = f.dof > 0 ? chi2 / f.dof : 0.0;
  const double inflate = std::max(1.0, f.chi2_dof);
  const gsl_vector* p = gsl_multifit_nlinear_position(w);
  const double a = gsl_vector_get(p, 0), b = gsl_vector_get(p, 1);
  f.eta_inf = std::exp(a);
  f.eta_inf_err = f.eta_inf * std::sqrt(inflate * gsl_matrix_get(cov, 0, 0));
  f.mason_star = std::exp(b);
  f.mason_star_err = f.mason_star * std::sqrt(inflate * gsl_matrix_get(cov, 1, 1));
  f.exponent = gsl_vector_get(p, 2);
  f.exponent_err = std::sqrt(inflate * gsl_matrix_get(cov, 2, 2));
  f.ok = status == GSL_SUCCESS && std::isfinite(f.exponent_err) && f.exponent > 0;
  if (!f.ok) f.message = status == GSL_SUCCESS ? "fit is ill-conditioned" : gsl_strerror(status);
  gsl_matrix_free(cov);
  gsl_multifit_nlinear_free(w);
  return f;
}

}  // namespace mrf
