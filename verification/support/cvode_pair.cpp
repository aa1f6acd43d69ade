#include "support/cvode_pair.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <set>
#include <stdexcept>

#include "mrf/forces/dipole.hpp"
#include "mrf/forces/hertz.hpp"

namespace mrf::test {

PairProblem iron_pair(double r0, double angle, double youngs) {
  PairProblem pb;
  SceneConfig& c = pb.scene;
  c.radius = 2.5e-6;
  c.density = 7800;
  c.magnetization = 1e6;
  c.viscosity = 0.1;
  c.youngs_modulus = youngs;
  c.poisson_ratio = 0.3;
  c.dipole_cutoff = 50e-6;
  c.shear_rate = 0;
  pb.params = dem_params(c);
  pb.box = Box{1e-3, 1e-3, 1e-3};
  // Centre near the origin: positions then resolve ~1e-21 m, far below the
  // errors measured (at y = 5e-4 m the rounding of 1e6 steps reaches 1e-16 m).
  const Vec3 centre(0, 20e-6, 20e-6);
  const Vec3 half = 0.5 * r0 * Vec3(std::cos(angle), std::sin(angle), 0);
  pb.x0 = {centre - half, centre + half};
  return pb;
}

PairPositions pair_forces(const DemParams& p, const PairPositions& x) {
  const Vec3 r_ik = x[0] - x[1];
  Vec3 f = Vec3::Zero();
  if (r_ik.squaredNorm() < p.dipole_cutoff * p.dipole_cutoff) f += dipole_force_x(r_ik, p.dipole_pref);
  f += hertz_pair_force(r_ik, 2.0 * p.radius, p.hertz_k);
  return {f, Vec3(-f)};
}

namespace {
PairPositions positions(const double* y) {
  return {Vec3(y[0], y[1], y[2]), Vec3(y[3], y[4], y[5])};
}
}  // namespace

void inertial_rhs(const DemParams& p, const double* y, double* ydot) {
  const PairPositions f = pair_forces(p, positions(y));
  for (int i = 0; i < 2; ++i)
    for (int d = 0; d < 3; ++d) {
      const double v = y[6 + 3 * i + d];
      ydot[3 * i + d] = v;
      ydot[6 + 3 * i + d] = (f[static_cast<std::size_t>(i)][d] - p.gamma * v) / p.mass;
    }
}

void inertialess_rhs(const DemParams& p, const double* y, double* ydot) {
  const PairPositions f = pair_forces(p, positions(y));
  for (int i = 0; i < 2; ++i)
    for (int d = 0; d < 3; ++d) ydot[3 * i + d] = f[static_cast<std::size_t>(i)][d] / p.gamma;
}

double closed_form_contact_time(const SceneConfig& c, double r0) {
  const double M = c.magnetization;
  return 9.0 * c.viscosity / (40.0 * k_mu0 * M * M) * (std::pow(r0 / c.radius, 5) - 32.0);
}

double closed_form_distance(const SceneConfig& c, double r0, double t) {
  const double m = dipole_moment(c.radius, c.magnetization);
  const double A = k_mu0 * m * m / (2.0 * k_pi * k_pi * c.viscosity * c.radius);
  return std::pow(std::pow(r0, 5) - 5.0 * A * t, 0.2);
}

DemRun run_dem(const PairProblem& pb, IntegratorId scheme, double dt, const std::vector<double>& t_out) {
  ShearCell cell;
  cell.box = pb.box;
  cell.free.x = {pb.x0[0], pb.x0[1]};
  cell.free.v.assign(2, Vec3::Zero());
  cell.free.f.assign(2, Vec3::Zero());
  DemRun run;
  const auto start = std::chrono::steady_clock::now();
  DemModel model(std::move(cell), pb.params, scheme, dt);
  for (double t : t_out) {
    const long n = std::lround(t / dt);
    if (std::abs(static_cast<double>(n) * dt - t) > 1e-9 * t)
      throw std::invalid_argument("run_dem: output time is not a whole number of steps");
    while (model.steps() < n) model.step();
    run.x.push_back({model.cell().free.x[0], model.cell().free.x[1]});
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.steps = model.steps();
  return run;
}

double position_error(const PairPositions& a, const PairPositions& b) {
  return std::max((a[0] - b[0]).norm(), (a[1] - b[1]).norm());
}

std::vector<double> output_times(double t_contact, double dt0, double grid, double t_end) {
  if (!(t_contact > 0)) throw std::invalid_argument("output_times: the pair never touches");
  const long g = std::lround(grid / dt0), n_end = std::lround(t_end / dt0);
  const long fine_lo = static_cast<long>(t_contact / grid) * g;
  std::set<long> n;
  for (long i = g; i <= n_end; i += g) n.insert(i);
  for (long k = 1; k < 200; ++k) n.insert(fine_lo + k);
  std::vector<double> t;
  for (long i : n) t.push_back(static_cast<double>(i) * dt0);
  return t;
}

WindowErrors window_errors(const std::vector<PairPositions>& x, const std::vector<PairPositions>& ref,
                           const std::vector<double>& t, double t_contact) {
  WindowErrors e;
  for (std::size_t j = 0; j < t.size(); ++j) {
    double& w = t[j] < t_contact ? e.pre : e.contact;
    w = std::max(w, position_error(x[j], ref[j]));
  }
  e.end = position_error(x.back(), ref.back());
  return e;
}

std::filesystem::path report_dir() {
  const char* env = std::getenv("MRF_REPORT_DIR");
  std::filesystem::path dir = env && *env ? std::filesystem::path(env) : std::filesystem::path("reports_out");
  std::filesystem::create_directories(dir);
  return dir;
}

void write_work_precision_csv(const std::filesystem::path& file, const std::vector<WorkPrecisionRow>& rows) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot write " + file.string());
  out << "integrator,dt_s,error_m,wall_s,steps\n" << std::setprecision(6);
  for (const auto& r : rows)
    out << r.integrator << ',' << r.dt_s << ',' << r.error_m << ',' << r.wall_s << ',' << r.steps << '\n';
}

}  // namespace mrf::test
