#include <nlohmann/json.hpp>

#include <cmath>

#include "mrf/observe/block_average.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/version.hpp"

namespace mrf {

std::string summary_json(const RunSummary& s) {
  nlohmann::ordered_json j;
  auto put = [&j](const std::string& key, const Measurement& m) {
    j[key] = m.mean;
    j[key + "_err"] = m.err;
    j[key + "_drift_z"] = m.drift_z;
    j[key + "_independent_samples"] = m.independent_samples;
  };
  j["model"] = s.model;
  // JSON has no infinity: Mn is infinite at magnetization 0 (drive.shear_rate
  // given), written as null with the reason beside it.
  if (std::isfinite(s.mason)) {
    j["mason"] = s.mason;
  } else {
    j["mason"] = nullptr;
    j["mason_note"] = s.magnetization == 0 ? "infinite: particles.magnetization = 0 (no magnetic forces)"
                                           : "not finite";
  }
  j["mason_convention"] = "Mn = 9 eta gdot / (2 mu0 M^2)";
  j["shear_rate"] = s.shear_rate;
  j["strain"] = s.strain;
  j["warmup_strain"] = s.warmup_strain;
  j["error_estimate_version"] = k_error_estimate_version;
  put("stress_total", s.stress_total);
  put("stress_particles", s.stress_particles);
  j["stress_fluid"] = s.stress_fluid;
  put("stress_virial", s.stress_virial);
  put("stress_virial_magnetic", s.stress_virial_magnetic);
  put("stress_virial_contact", s.stress_virial_contact);
  put("stress_wall_minus_virial", s.wall_minus_virial);
  j["n_particles"] = s.n_particles;
  j["n_wall"] = s.n_wall;
  j["n_fluid"] = s.n_fluid;
  j["integrator"] = s.integrator;
  j["dt"] = s.dt;
  j["dt_bound_by"] = s.binding_limit;
  j["steps"] = s.steps;
  j["neighbor_builds"] = s.neighbor_builds;
  j["wall_seconds"] = s.wall_seconds;
  j["cpu_seconds"] = s.cpu_seconds;
  j["particle_steps_per_second"] = s.particle_steps_per_second;
  j["pair_evaluations_per_second"] = s.pair_evaluations_per_second;
  j["threads"] = s.threads;
  j["stokes_number"] = s.stokes_number;
  j["reynolds_number"] = s.reynolds_number;
  j["max_overlap_over_radius"] = s.max_overlap_over_radius;
  j["youngs_modulus"] = s.youngs_modulus;
  j["particle_density"] = s.density;
  j["magnetization"] = s.magnetization;
  j["volume_fraction"] = s.volume_fraction;
  j["viscosity"] = s.viscosity;          // Pa s, the carrier fluid's (mrf criterion reads it)
  j["fluid_density"] = s.fluid_density;  // kg/m^3
  j["seed"] = s.seed;
  j["scene_id"] = s.scene_id;
  for (const auto& [key, value] : s.extra) j[key] = value;
  j["version"] = version();
  j["git_revision"] = git_revision();
  return j.dump(2);
}

}  // namespace mrf
