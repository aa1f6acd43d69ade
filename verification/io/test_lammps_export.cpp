// Export of a shear cell to LAMMPS (io/lammps_data.hpp), the input of the
// LAMMPS peer benchmark (benchmarks/peers/lammps/). The small scene of
// experiments/scenes/small_dem_stokes.toml is written to a temporary
// directory and parsed back:
// - PREFIX.data: header counts, box bounds (x holds the walls, y and z the
//   periodic lengths), one Atoms line per sphere in the column order of
//   atom_style hybrid sphere dipole (id type x y z diameter density q mux
//   muy muz), positions exactly those of the cell, type 1 = free spheres
//   with the scene's moment along +x, type 2 = wall spheres without moment,
//   mass = density x volume, and a Velocities line per atom (id vx vy vz
//   wx wy wz) with the Couette velocity (0, 0, gdot x) and no spin;
// - PREFIX.params: each `variable NAME equal VALUE` equals the DemParams
//   value, and hertz_kn is LAMMPS' Hertz constant (F = kn sqrt(R_eff h) h,
//   pair gran/hertz/history) for mrf's F = k h^1.5: kn sqrt(R/2) = k,
//   kn = (4/3) E* = (2/3) Y / (1 - nu^2) (REFERENCE §2).
// The values are written with 17 significant digits, so doubles round-trip
// exactly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "mrf/forces/drag.hpp"
#include "mrf/io/lammps_data.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/dem_params.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {
namespace {

namespace fs = std::filesystem;

const std::string k_small_scene = MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml";

// A fresh directory under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(fs::temp_directory_path() / ("mrf_lammps_" + tag + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

struct AtomLine {
  long id;
  int type;
  Vec3 x;
  double diameter, density, q;
  Vec3 mu;
};

struct VelocityLine {
  Vec3 v, omega;
};

struct DataFile {
  long atoms = -1;
  int atom_types = -1;
  double xlo = 0, xhi = 0, ylo = 0, yhi = 0, zlo = 0, zhi = 0;
  std::string atoms_style_hint;
  std::vector<AtomLine> atom_lines;
  std::map<long, VelocityLine> velocities;
  int bad_atom_lines = 0, bad_velocity_lines = 0;
};

std::vector<std::string> split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// A LAMMPS data file: header lines until the first section keyword, then the
// Atoms and Velocities sections (a section ends at the next keyword line).
DataFile parse_data_file(const std::string& path) {
  std::ifstream in(path);
  DataFile d;
  std::string line, section;
  bool header = true;
  std::getline(in, line);  // the first line is a comment
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    const std::string body = line.substr(0, hash);
    const auto w = split(body);
    if (w.empty()) continue;
    if (w.size() == 1 && (w[0] == "Atoms" || w[0] == "Velocities")) {
      header = false;
      section = w[0];
      if (section == "Atoms" && hash != std::string::npos) {
        std::string hint = line.substr(hash + 1);
        hint.erase(0, hint.find_first_not_of(' '));
        d.atoms_style_hint = hint;
      }
      continue;
    }
    if (header) {
      if (w.size() == 2 && w[1] == "atoms") d.atoms = std::stol(w[0]);
      if (w.size() == 3 && w[1] == "atom" && w[2] == "types") d.atom_types = std::stoi(w[0]);
      if (w.size() == 4 && w[2] == "xlo") d.xlo = std::stod(w[0]), d.xhi = std::stod(w[1]);
      if (w.size() == 4 && w[2] == "ylo") d.ylo = std::stod(w[0]), d.yhi = std::stod(w[1]);
      if (w.size() == 4 && w[2] == "zlo") d.zlo = std::stod(w[0]), d.zhi = std::stod(w[1]);
      continue;
    }
    if (section == "Atoms") {
      if (w.size() != 11) {
        ++d.bad_atom_lines;
        continue;
      }
      AtomLine a{std::stol(w[0]), std::stoi(w[1]),
                 Vec3(std::stod(w[2]), std::stod(w[3]), std::stod(w[4])),
                 std::stod(w[5]), std::stod(w[6]), std::stod(w[7]),
                 Vec3(std::stod(w[8]), std::stod(w[9]), std::stod(w[10]))};
      d.atom_lines.push_back(a);
    } else if (section == "Velocities") {
      if (w.size() != 7) {
        ++d.bad_velocity_lines;
        continue;
      }
      d.velocities[std::stol(w[0])] = {Vec3(std::stod(w[1]), std::stod(w[2]), std::stod(w[3])),
                                       Vec3(std::stod(w[4]), std::stod(w[5]), std::stod(w[6]))};
    }
  }
  return d;
}

// `variable NAME equal VALUE  # comment` lines of a LAMMPS include file.
std::map<std::string, double> parse_params(const std::string& path) {
  std::ifstream in(path);
  std::map<std::string, double> vars;
  for (std::string line; std::getline(in, line);) {
    const auto w = split(line.substr(0, line.find('#')));
    if (w.size() == 4 && w[0] == "variable" && w[2] == "equal") vars[w[1]] = std::stod(w[3]);
  }
  return vars;
}

struct Exported {
  LoadedScene scene;
  DemParams p;
  ShearCell cell;
};

Exported small_scene(const std::vector<std::string>& overrides = {}) {
  LoadedScene scene = load_scene(k_small_scene, overrides);
  const DemParams p = dem_params(scene.config);
  ShearCell cell = build_shear_cell(scene.config);
  return {std::move(scene), p, std::move(cell)};
}

TEST(LammpsExport, DataFileHasTheCellsSpheresMomentsAndCouetteVelocities) {
  const Exported e = small_scene();
  const ShearCell& cell = e.cell;
  const DemParams& p = e.p;
  ASSERT_GT(cell.free.size(), 0u);
  ASSERT_GT(cell.walls.size(), 0u);
  TempDir dir("data");
  write_lammps_data(cell, p, dir.file("scene.data"));
  const DataFile d = parse_data_file(dir.file("scene.data"));

  const std::size_t n_free = cell.free.size(), n_wall = cell.walls.size();
  EXPECT_EQ(d.atoms, static_cast<long>(n_free + n_wall));
  EXPECT_EQ(d.atom_types, 2);
  EXPECT_EQ(d.atoms_style_hint, "hybrid sphere dipole");
  EXPECT_EQ(d.bad_atom_lines, 0);
  EXPECT_EQ(d.bad_velocity_lines, 0);
  ASSERT_EQ(d.atom_lines.size(), n_free + n_wall);

  // Box: y and z are the periodic lengths; x is bounded (boundary f) and
  // must hold the wall spheres whole (centres at -+gap/2, radius R).
  EXPECT_EQ(d.ylo, 0.0);
  EXPECT_EQ(d.yhi, cell.box.ly);
  EXPECT_EQ(d.zlo, 0.0);
  EXPECT_EQ(d.zhi, cell.box.lz);
  EXPECT_DOUBLE_EQ(d.xlo, -d.xhi);
  EXPECT_GE(d.xhi, 0.5 * cell.box.gap + p.radius);
  EXPECT_LE(d.xhi, 0.5 * cell.box.gap + 4.0 * p.radius);  // no needless empty space

  const double volume = 4.0 / 3.0 * std::numbers::pi * p.radius * p.radius * p.radius;
  std::set<long> ids;
  std::size_t n_type1 = 0, n_type2 = 0;
  for (std::size_t n = 0; n < d.atom_lines.size(); ++n) {
    const AtomLine& a = d.atom_lines[n];
    ids.insert(a.id);
    EXPECT_EQ(a.diameter, 2.0 * p.radius) << "atom " << a.id;
    EXPECT_NEAR(a.density * volume, p.mass, 1e-14 * p.mass) << "atom " << a.id;
    EXPECT_EQ(a.q, 0.0) << "atom " << a.id;
    EXPECT_GE(a.x.x(), d.xlo);
    EXPECT_LE(a.x.x(), d.xhi);
    EXPECT_GE(a.x.y(), d.ylo);
    EXPECT_LT(a.x.y(), d.yhi);
    EXPECT_GE(a.x.z(), d.zlo);
    EXPECT_LT(a.x.z(), d.zhi);
    if (a.type == 1) {
      ASSERT_LT(n, n_free) << "free spheres come first";
      ++n_type1;
      EXPECT_EQ(a.x, cell.free.x[n]) << "atom " << a.id;
      EXPECT_EQ(a.mu, Vec3(p.moment, 0.0, 0.0)) << "atom " << a.id;
    } else {
      ASSERT_EQ(a.type, 2) << "atom " << a.id;
      ASSERT_GE(n, n_free);
      ++n_type2;
      EXPECT_EQ(a.x, cell.walls.x[n - n_free]) << "atom " << a.id;
      EXPECT_EQ(a.mu, Vec3::Zero()) << "atom " << a.id;
      EXPECT_NEAR(std::abs(a.x.x()), 0.5 * cell.box.gap, 1e-12 * cell.box.gap);
    }
  }
  EXPECT_EQ(n_type1, n_free);
  EXPECT_EQ(n_type2, n_wall);
  EXPECT_EQ(ids.size(), n_free + n_wall) << "atom ids must be unique";
  EXPECT_EQ(*ids.begin(), 1);
  EXPECT_EQ(*ids.rbegin(), static_cast<long>(n_free + n_wall));

  // Velocities: the imposed Couette profile for every atom; the walls move
  // with -+gdot gap/2 (lower wall -z).
  ASSERT_EQ(d.velocities.size(), n_free + n_wall);
  const double wall_speed = 0.5 * cell.box.gap * p.shear_rate;
  for (const AtomLine& a : d.atom_lines) {
    const auto it = d.velocities.find(a.id);
    ASSERT_NE(it, d.velocities.end()) << "no velocity for atom " << a.id;
    const VelocityLine& v = it->second;
    EXPECT_EQ(v.v.x(), 0.0);
    EXPECT_EQ(v.v.y(), 0.0);
    EXPECT_NEAR(v.v.z(), p.shear_rate * a.x.x(), 1e-15 * wall_speed) << "atom " << a.id;
    EXPECT_EQ(v.omega, Vec3::Zero()) << "atom " << a.id;
    if (a.type == 2) {
      EXPECT_NEAR(v.v.z(), std::copysign(wall_speed, a.x.x()), 1e-12 * wall_speed);
    }
  }
}

TEST(LammpsExport, ParamsFileHoldsTheDemParametersAndLammpsHertzConstant) {
  for (const char* mason : {"drive.mason=1e-2", "drive.mason=0.3"}) {
    SCOPED_TRACE(mason);
    const Exported e = small_scene({mason});
    const DemParams& p = e.p;
    const SceneConfig& c = e.scene.config;
    const double dt = 1.2345678901234567e-9;
    TempDir dir("params");
    write_lammps_params(p, e.cell.box, dt, dir.file("scene.params"));
    const auto v = parse_params(dir.file("scene.params"));

    const std::map<std::string, double> expected = {
        {"radius", p.radius},       {"mass", p.mass},
        {"moment", p.moment},       {"gamma", p.gamma},
        {"tau_p", p.tau_p},         {"hertz_k", p.hertz_k},
        {"dipole_cutoff", p.dipole_cutoff}, {"skin", p.skin},
        {"shear_rate", p.shear_rate}, {"gap", e.cell.box.gap},
        {"dt_mrf", dt}};
    for (const auto& [name, value] : expected) {
      const auto it = v.find(name);
      ASSERT_NE(it, v.end()) << "missing variable " << name;
      EXPECT_EQ(it->second, value) << name;
    }
    ASSERT_TRUE(v.count("wall_speed"));
    EXPECT_NEAR(v.at("wall_speed"), 0.5 * c.gap * c.shear_rate, 1e-15 * v.at("wall_speed"));
    EXPECT_NEAR(v.at("tau_p"), v.at("mass") / v.at("gamma"), 1e-15 * v.at("tau_p"));
    EXPECT_NEAR(v.at("shear_rate"), shear_rate_from_mason(c.mason, c.viscosity, c.magnetization),
                1e-14 * v.at("shear_rate"));

    // LAMMPS Hertz: F = kn h sqrt(h R_i R_j / (R_i + R_j)) = kn sqrt(R/2) h^1.5.
    ASSERT_TRUE(v.count("hertz_kn"));
    const double kn = v.at("hertz_kn");
    EXPECT_NEAR(kn * std::sqrt(0.5 * p.radius), p.hertz_k, 1e-14 * p.hertz_k);
    const double nu = c.poisson_ratio;
    EXPECT_NEAR(kn, 2.0 / 3.0 * c.youngs_modulus / (1.0 - nu * nu), 1e-14 * kn);
    // And the force it gives at a small overlap is mrf's (REFERENCE §2).
    const double h = 1e-3 * p.radius;
    const double lammps_force = kn * h * std::sqrt(h * p.radius * p.radius / (2.0 * p.radius));
    EXPECT_NEAR(lammps_force, p.hertz_k * std::pow(h, 1.5), 1e-13 * lammps_force);
  }
}

}  // namespace
}  // namespace mrf
