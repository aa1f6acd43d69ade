// A validated scene: every parameter of a run in SI units, as read from a
// scene file (io/toml_scene.hpp) or built by a test. Defaults are documented
// here and in docs/scene-format.md.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "mrf/params.hpp"

namespace mrf {

// dem_dd is not one of the study's three models: it is model 1 (one-way, an
// imposed Couette carrier) with the Di Felice drag at Re -> 0 and the cell's
// mean porosity 1 - phi in place of Stokes', a probe of how much of model 3's
// stress its porosity-dependent drag alone explains (the second, cheaper
// estimate of the criterion, issue 14: docs/study.md).
enum class ModelId { dem_stokes, demsph_stokes, demsph_dd, dem_dd };
// The one-way models: particles in an imposed carrier, no SPH.
inline bool is_one_way(ModelId m) { return m == ModelId::dem_stokes || m == ModelId::dem_dd; }
// What sets the Mason number (REFERENCE §8, "How the Mason number is
// varied"): the shear rate at the given magnetisation, or the magnetisation
// at the given shear rate, M = sqrt(9 eta gdot / (2 mu0 Mn)).
enum class MasonBy { shear_rate, magnetization };
// The SPH carrier's equation-of-state reference in the coupled models
// (fluid.eos_reference): the fluid density for every particle (REFERENCE §6's
// model, the default since session 37), or each SPH particle's intrinsic
// density rho/eps at the start, so that the start carries no pressure from
// the porosity field (the default before; the paper study pins it:
// docs/study.md, "The carrier's wall layer").
enum class EosReference { start, common };

const char* to_string(ModelId m);
const char* to_string(MasonBy v);
const char* to_string(EosReference v);

struct SceneConfig {
  // [scene]
  ModelId model = ModelId::dem_stokes;
  std::uint64_t seed = 1;
  // [box] (m)
  double gap = 0, ly = 0, lz = 0;
  // [particles]
  double radius = 0;           // m
  double volume_fraction = 0;  // n V_p / (gap ly lz), 0 allowed (no magnetic particles)
  double density = 0;          // kg/m^3
  double magnetization = 0;    // A/m, fixed along +x
  double dipole_cutoff = 0;    // m, centre-centre distance beyond which dipole forces vanish
  // [walls]
  double wall_spacing = 0;     // m, lattice spacing of the wall spheres in y and z
  // [contact]
  double youngs_modulus = 0;   // Pa
  double poisson_ratio = 0;    // 1
  // [fluid]
  double viscosity = 0;        // Pa s
  double fluid_density = 0;    // kg/m^3
  double sph_spacing = 0;      // m, SPH particle spacing (SPH models only)
  double sound_speed = 0;      // m/s (SPH models only; 0 = choose from 1 % density variation)
  EosReference eos_reference = EosReference::common;  // coupled models only
  // [drive]: exactly one of mason, shear_rate is given in the file; both are
  // filled in after validation (Mn = 9 eta gdot / (2 mu0 M^2), DESIGN.md).
  // Mn = +inf for drive.shear_rate with magnetization = 0 (no magnetic
  // forces); drive.mason with magnetization = 0 is refused. With
  // vary = "magnetization" both are given and particles.magnetization is
  // derived from them (a value in the file is replaced).
  MasonBy vary = MasonBy::shear_rate;
  double mason = 0;
  double shear_rate = 0;       // 1/s
  double strain = 0;           // total strain of the run
  double warmup_strain = 0;    // strain discarded before averaging
  // [numerics]
  IntegratorId integrator = IntegratorId::automatic;
  std::optional<double> dt;    // s; empty = automatic
  double skin = 0;             // m, Verlet skin; 0 = chosen for cost, starting from 0.2 radius (0.8 implicit)
  double dt_safety = 0.5;      // fraction of the smallest stability limit used by automatic dt
  double implicit_tol = 1e-2;  // implicit scheme: largest local error per step / radius
  int implicit_order = 2;      // implicit scheme: 1 (IMEX Euler) or 2 (IMEX BDF2)
  double newton_tol = 1e-6;    // implicit scheme: Newton converged when every overlap residual / radius is below it
  int threads = 1;             // OpenMP threads; 0 = the OpenMP default (all cores or OMP_NUM_THREADS)
  // [output]
  int every = 0;               // steps between time-series rows; 0 = about 2000 rows per run
  int frames = 0;              // number of particle frames written (0 = none)
};

// Mason number from shear rate and back (DESIGN.md convention).
// Sets the OpenMP thread count of the scene's numerics.threads (0 leaves
// the OpenMP default); every command that runs a scene calls it.
void use_scene_threads(const SceneConfig& c);
double mason_from_shear_rate(double shear_rate, double viscosity, double magnetization);
double shear_rate_from_mason(double mason, double viscosity, double magnetization);
double magnetization_from_mason(double mason, double viscosity, double shear_rate);

// Whether the drive quantity derived from the others (M with drive.vary =
// "magnetization", gdot from a given Mn, else Mn) is finite and positive: an
// extreme viscosity or magnetisation can overflow it to inf or flush it to 0.
// The key to blame and why, or nothing.
struct DriveProblem {
  std::string key, why;
};
std::optional<DriveProblem> derived_drive_problem(const SceneConfig& c, bool mason_given);

}  // namespace mrf
