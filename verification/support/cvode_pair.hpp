// The two-sphere problem of REFERENCE.md TEST 1.2 / 1.4 for comparing the DEM
// integrators with a CVODE reference (verification/integrate/test_cvode_reference.cpp):
// two free magnetic spheres released at rest, attracted by their dipoles,
// damped by Stokes drag, stopped by Hertz contact. This part holds no SUNDIALS
// calls: the problem, the reference right-hand sides built from the library's
// force laws, the DEM driver and the CSV writer.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "mrf/scene/dem_model.hpp"

namespace mrf::test {

using PairPositions = std::array<Vec3, 2>;

struct PairProblem {
  SceneConfig scene;  // material, fluid and dipole cut-off (SI)
  DemParams params;   // derived with dem_params(scene)
  Box box;            // 1 mm cube: periodic images are irrelevant
  PairPositions x0;   // initial centres (m), released at rest
};

// Iron spheres (R = 2.5 um, rho = 7800, M = 1e6 A/m along +x, eta = 0.1 Pa s,
// nu = 0.3, Young's modulus `youngs` in Pa), centre distance r0 (m), the line
// of centres at `angle` (rad) from the field, in the x-y plane; cut-off 50 um.
PairProblem iron_pair(double r0, double angle, double youngs = 200e9);

// Non-drag forces on both spheres (N): dipole_force_x within the cut-off plus
// the Hertz law, the same laws and the same r_ik = x_0 - x_1 as the DEM model.
PairPositions pair_forces(const DemParams& p, const PairPositions& x);

// Right-hand sides for the reference integrator. Inertial (12 dof), state
// y = (x_0, x_1, v_0, v_1): dx/dt = v, m dv/dt = F - gamma v. Inertialess
// (6 dof), y = (x_0, x_1): gamma dx/dt = F. `ydot` has the size of `y`.
void inertial_rhs(const DemParams& p, const double* y, double* ydot);
void inertialess_rhs(const DemParams& p, const double* y, double* ydot);

// TEST 1.2: contact time of the inertialess head-to-tail pair,
// T = (9 eta / 40 mu0 M^2) [(r0/R)^5 - 32] (s), and the distance
// r(t) = (r0^5 - 5 A t)^{1/5}, A = mu0 m^2 / (2 pi^2 eta R) (m).
double closed_form_contact_time(const SceneConfig& c, double r0);
double closed_form_distance(const SceneConfig& c, double r0, double t);

// One DEM run with the library's model: positions at the output times (each
// a whole number of steps), wall time of the stepping (s) and steps taken.
struct DemRun {
  std::vector<PairPositions> x;
  double wall_s = 0;
  long steps = 0;
};
DemRun run_dem(const PairProblem& pb, IntegratorId scheme, double dt, const std::vector<double>& t_out);

// Largest distance between corresponding centres (m).
double position_error(const PairPositions& a, const PairPositions& b);

// Output times (s) up to t_end: every `grid`, and every dt0 for 200 dt0 from
// the last grid point before t_contact (resolving a fast contact transient).
// Built on integers: with grid a multiple of dt0, each time is a whole number
// of steps of every dt0 / 2^l. Throws when t_contact <= 0 (no contact).
std::vector<double> output_times(double t_contact, double dt0, double grid, double t_end);

// Errors of a run against a reference on the same output times t: the largest
// position error before the reference's first contact, the largest from
// contact on (impact, bounces, settling), and the error at the last time (m).
struct WindowErrors {
  double pre = 0, contact = 0, end = 0;
};
WindowErrors window_errors(const std::vector<PairPositions>& x, const std::vector<PairPositions>& ref,
                           const std::vector<double>& t, double t_contact);

// One row of work_precision_dem_pair.csv (reports/work_precision/README.md).
struct WorkPrecisionRow {
  std::string integrator;
  double dt_s, error_m, wall_s;
  long steps;
};
// $MRF_REPORT_DIR if set, else ./reports_out; created when missing.
std::filesystem::path report_dir();
void write_work_precision_csv(const std::filesystem::path& file, const std::vector<WorkPrecisionRow>& rows);

}  // namespace mrf::test
