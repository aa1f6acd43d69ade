#include "mrf/io/lammps_data.hpp"

#include <cmath>
#include <fstream>

#include "mrf/error.hpp"
#include "mrf/forces/drag.hpp"

namespace mrf {

namespace {
std::ofstream open_or_throw(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InputError("--out", path, "", "cannot write the file");
  out.precision(17);
  return out;
}
}  // namespace

void write_lammps_data(const ShearCell& cell, const DemParams& p, const std::string& path) {
  std::ofstream out = open_or_throw(path);
  const double half_x = 0.5 * cell.box.gap + 2.0 * p.radius;
  const double density = p.mass / sphere_volume(p.radius);
  out << "LAMMPS data file from mrf: shear cell, SI units, atom_style hybrid sphere dipole\n\n"
      << cell.free.size() + cell.walls.size() << " atoms\n2 atom types\n\n"
      << -half_x << " " << half_x << " xlo xhi\n0 " << cell.box.ly << " ylo yhi\n0 " << cell.box.lz
      << " zlo zhi\n\nAtoms # hybrid sphere dipole\n\n";
  // columns: id type x y z diameter density q mux muy muz
  std::size_t id = 1;
  for (const Vec3& x : cell.free.x)
    out << id++ << " 1 " << x.x() << " " << x.y() << " " << x.z() << " " << 2 * p.radius << " "
        << density << " 0 " << p.moment << " 0 0\n";
  for (const Vec3& x : cell.walls.x)
    out << id++ << " 2 " << x.x() << " " << x.y() << " " << x.z() << " " << 2 * p.radius << " "
        << density << " 0 0 0 0\n";
  out << "\nVelocities\n\n";
  id = 1;
  for (const Vec3& x : cell.free.x) out << id++ << " 0 0 " << couette_velocity(x, p.shear_rate).z() << " 0 0 0\n";
  for (const Vec3& x : cell.walls.x) out << id++ << " 0 0 " << couette_velocity(x, p.shear_rate).z() << " 0 0 0\n";
}

void write_lammps_params(const DemParams& p, const Box& box, double dt, const std::string& path) {
  std::ofstream out = open_or_throw(path);
  const double r_eff = 0.5 * p.radius;
  auto var = [&out](const char* name, double v, const char* what) {
    out << "variable " << name << " equal " << v << "  # " << what << "\n";
  };
  out << "# mrf scene parameters (SI), written by `mrf export-lammps`\n";
  var("radius", p.radius, "m");
  var("mass", p.mass, "kg");
  var("moment", p.moment, "A m^2, fixed along +x");
  var("gamma", p.gamma, "Stokes friction 6 pi eta R, kg/s");
  var("tau_p", p.tau_p, "drag relaxation m/gamma, s");
  var("hertz_k", p.hertz_k, "F = k h^1.5, N/m^1.5");
  var("hertz_kn", p.hertz_k / std::sqrt(r_eff), "LAMMPS Hertz: F = kn sqrt(R_eff h) h, R_eff = R/2, Pa");
  var("dipole_cutoff", p.dipole_cutoff, "m");
  var("skin", p.skin, "m");
  var("shear_rate", p.shear_rate, "1/s");
  var("gap", box.gap, "wall-centre distance, m");
  var("wall_speed", 0.5 * box.gap * p.shear_rate, "upper wall +z, lower wall -z, m/s");
  var("dt_mrf", dt, "mrf's automatic time step, s");
}

}  // namespace mrf
