#include "mrf/scene/run_series.hpp"

#include <algorithm>
#include <string>

#include "mrf/error.hpp"
#include "mrf/observe/block_average.hpp"
#include "mrf/observe/steady_state.hpp"
#include "mrf/observe/stress.hpp"

namespace mrf {

namespace {

Measurement measure(const std::vector<double>& v) {
  const BlockAverage b = block_average(v);
  return {b.mean, b.sem, b.drift_z};
}

}  // namespace

void SeriesRow::add(const PairSums& p, const Box& box, double fluid_stress, double fluid_virial, double w) {
  vir_fluid += w * fluid_virial;
  particles += w * wall_shear_stress(p.wall_fz, box);
  fluid += w * fluid_stress;
  vir_mag += w * virial_shear_stress(p.virial_mag_xz, box);
  vir_con += w * virial_shear_stress(p.virial_con_xz, box);
  max_overlap = std::max(max_overlap, p.max_overlap);
  e_dip += w * p.energy_dipole;
  e_hertz += w * p.energy_hertz;
  n += w;
}

void StressSeries::push(const SeriesRow& r) {
  const double k = 1.0 / r.n;
  const double tp = r.particles * k, tf = r.fluid * k, vm = r.vir_mag * k, vc = r.vir_con * k;
  total_.push_back(tp + tf);
  particles_.push_back(tp);
  fluid_.push_back(tf);
  virial_.push_back(vm + vc);
  mag_.push_back(vm);
  con_.push_back(vc);
  diff_.push_back(tp - vm - vc);
  vir_fluid_.push_back(r.vir_fluid * k);
  vir_total_.push_back(vm + vc + r.vir_fluid * k);
}

Measurement StressSeries::fluid() const { return measure(fluid_); }

void StressSeries::save(ArchiveWriter& a) const {
  for (const auto* v : {&total_, &particles_, &fluid_, &virial_, &mag_, &con_, &diff_, &vir_fluid_, &vir_total_}) a.put(*v);
}

void StressSeries::load(ArchiveReader& a) {
  for (auto* v : {&total_, &particles_, &fluid_, &virial_, &mag_, &con_, &diff_, &vir_fluid_, &vir_total_}) a.get(*v);
}

void StressSeries::finish(RunSummary& s) const {
  s.stress_total = measure(total_);
  s.stress_particles = measure(particles_);
  s.stress_fluid = measure(fluid_).mean;
  s.stress_virial = measure(virial_);
  s.stress_virial_magnetic = measure(mag_);
  s.stress_virial_contact = measure(con_);
  s.wall_minus_virial = measure(diff_);
  const Measurement vt = measure(vir_total_);
  s.extra["stress_virial_total"] = vt.mean;
  s.extra["stress_virial_total_err"] = vt.err;
  s.extra["stress_virial_fluid"] = measure(vir_fluid_).mean;
  // steady-state check: the share of the averaging window MSER-5 would still
  // discard as transient (0 = steady from the end of the warm-up)
  s.extra["steady_mser_discard_fraction"] =
      total_.empty() ? 0.0 : static_cast<double>(mser_truncation(total_)) / static_cast<double>(total_.size());
}

void write_series_header(std::ostream& out) {
  out << "time_s,strain,stress_total_Pa,stress_particles_Pa,stress_fluid_Pa,"
         "stress_virial_magnetic_Pa,stress_virial_contact_Pa,max_overlap_over_radius,"
         "energy_dipole_J,energy_hertz_J\n";
}

void write_series_row(std::ostream& out, double time, double strain, const SeriesRow& r, double radius) {
  const double k = 1.0 / r.n;
  out << time << "," << strain << "," << (r.particles + r.fluid) * k << "," << r.particles * k << ","
      << r.fluid * k << "," << r.vir_mag * k << "," << r.vir_con * k << "," << r.max_overlap / radius << ","
      << r.e_dip * k << "," << r.e_hertz * k << "\n";
}

void write_frame(std::ostream& out, const ShearCell& cell, double radius, double time) {
  out << cell.free.size() + cell.walls.size() << "\n";
  out << "Lattice=\"" << cell.box.gap + 2 * radius << " 0 0 0 " << cell.box.ly << " 0 0 0 " << cell.box.lz
      << "\" Origin=\"" << -0.5 * cell.box.gap - radius
      << " 0 0\" Properties=species:S:1:pos:R:3:radius:R:1 Time=" << time << "\n";
  for (const auto& x : cell.free.x) out << "Fe " << x.x() << " " << x.y() << " " << x.z() << " " << radius << "\n";
  for (const auto& x : cell.walls.x) out << "W " << x.x() << " " << x.y() << " " << x.z() << " " << radius << "\n";
}

long series_every(const LoadedScene& scene, long steps) {
  const SceneConfig& c = scene.config;
  const long every = c.every > 0 ? c.every : std::max(1L, steps / 2000);
  const double rows_after_warmup = (1.0 - c.warmup_strain / c.strain) * static_cast<double>(steps / every);
  if (rows_after_warmup < 32)
    throw InputError("output.every", std::to_string(every), scene.locate("output.every"),
                     "leaves only " + std::to_string(static_cast<long>(rows_after_warmup)) +
                         " time-series rows after the warm-up; block averaging needs at least 32");
  return every;
}

}  // namespace mrf
