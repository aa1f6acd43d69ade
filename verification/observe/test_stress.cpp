// Stress observables on configurations with a known answer (REFERENCE.md
// TEST 1.5 and §7): the tilted ideal chain, a compressed gap-spanning strut
// in static equilibrium, and the exact virial identity on a shear cell.
#include <gtest/gtest.h>

#include <cmath>

#include "mrf/forces/dipole.hpp"
#include "mrf/observe/stress.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6, M = 1e6, Y = 200e9, nu = 0.3;

SceneConfig base_config() {
  SceneConfig c;
  c.radius = R;
  c.density = 7800;
  c.magnetization = M;
  c.youngs_modulus = Y;
  c.poisson_ratio = nu;
  c.viscosity = 0.1;
  c.dipole_cutoff = 15e-6;
  c.wall_spacing = R;
  c.gap = 80e-6;
  c.ly = c.lz = 32e-6;
  c.volume_fraction = 0.3;
  c.shear_rate = 1e3;
  return c;
}

// Virial sum r_ik,x F_ik,z of a straight chain of n touching-by-affine-stretch
// dipoles tilted by theta (x spacing 2R, so centre spacing 2R/cos(theta)).
double chain_virial(int n, double theta, const DemParams& p) {
  ShearCell cell;
  cell.box = Box{2.0 * n * 2 * R, 1.0, 1.0};  // no periodic image within reach
  const Vec3 step(2 * R, 0, 2 * R * std::tan(theta));
  for (int i = 0; i < n; ++i) cell.free.x.push_back(Vec3(-n * R, 0.5, 0.5) + i * step);
  cell.free.f.assign(n, Vec3::Zero());
  DemPairLists lists = make_pair_lists(p.dipole_cutoff, 0.0, 0.0);
  build_pair_lists(lists, cell.free, cell.walls, cell.box);
  return compute_dem_forces(p, cell.box, cell.free, cell.walls, lists).virial_mag_xz;
}

// TEST 1.5: tau(theta)/(phi mu0 M^2) = (3 zeta(3)/24) cos^4 sin (5 cos^2 - 1).
// Adding a sphere to a long chain adds one sphere's share of the infinite
// chain's virial (up to the tail sum_{n>N} n^-3 ~ 1/(2N^2)).
TEST(ChainVirial, TiltedIdealChainMatchesChainModel) {
  SceneConfig c = base_config();
  c.dipole_cutoff = 1.0;  // every pair of the chain
  const DemParams p = dem_params(c);
  constexpr double zeta3 = 1.2020569031595942;
  const int n = 200;
  for (double theta : {0.3712, 0.2, -0.2, 0.9, 1.2}) {
    const double per_sphere = chain_virial(n + 1, theta, p) - chain_virial(n, theta, p);
    // sigma = -(1/V) sum -> per sphere of volume V_p at volume fraction phi:
    const double tau_over_phi = -per_sphere / sphere_volume(R) / (k_mu0 * M * M);
    const double cs = std::cos(theta), sn = std::sin(theta);
    const double expect = 3 * zeta3 / 24 * std::pow(cs, 4) * sn * (5 * cs * cs - 1);
    EXPECT_NEAR(tau_over_phi, expect, 2e-5 * 0.137) << "theta " << theta;
  }
}

TEST(ChainVirial, YieldStressMaximumOfReference) {
  SceneConfig c = base_config();
  c.dipole_cutoff = 1.0;
  const DemParams p = dem_params(c);
  const int n = 200;
  const double tau = -(chain_virial(n + 1, 0.3712, p) - chain_virial(n, 0.3712, p)) /
                     sphere_volume(R) / (k_mu0 * M * M);
  EXPECT_NEAR(tau, 0.13738, 2e-5);
}

// A non-magnetic strut of free spheres compressed between one lower and one
// upper wall sphere, all collinear along n = (cos t, 0, sin t): every free
// sphere is force-free, and wall stress equals virial stress exactly.
TEST(StaticChain, CompressedStrutWallStressEqualsVirial) {
  SceneConfig c = base_config();
  c.magnetization = 0;
  const DemParams p = dem_params(c);
  const int n = 8;
  const double theta = 0.35, d = 2 * R - 2e-9;  // centre spacing, overlap 2 nm
  const Vec3 u(std::cos(theta), 0, std::sin(theta));
  ShearCell cell;
  cell.box = Box{(n + 1) * d * u.x(), 40e-6, 60e-6};
  const Vec3 start(-0.5 * cell.box.gap, 20e-6, 10e-6);
  cell.walls.x = {start, start + (n + 1) * d * u};
  cell.walls.side = {-1, 1};
  for (int i = 1; i <= n; ++i) cell.free.x.push_back(start + i * d * u);
  cell.free.f.assign(n, Vec3::Zero());
  DemPairLists lists = make_pair_lists(2 * R, 2 * R, 0.1 * R);
  build_pair_lists(lists, cell.free, cell.walls, cell.box);
  const PairSums s = compute_dem_forces(p, cell.box, cell.free, cell.walls, lists);
  const double load = p.hertz_k * std::pow(2 * R - d, 1.5);
  for (const Vec3& f : cell.free.f) EXPECT_LT(f.norm(), 1e-9 * load);
  const double wall = wall_shear_stress(s.wall_fz, cell.box);
  const double virial = virial_shear_stress(s.virial_con_xz, cell.box);
  const double expect = -load * std::sin(theta) / cell.box.wall_area();  // a pushing strut: negative
  EXPECT_NEAR(wall, expect, 1e-9 * std::abs(expect));
  EXPECT_NEAR(virial, expect, 1e-9 * std::abs(expect));
}

// x is not periodic, so sum_pairs r_ik,x F_ik,z = sum_i x_i F_i,z over free
// and wall spheres: the virial splits exactly into the wall stress and the
// first moment of the net particle forces, -(1/V) sum x_i f_i,z (which in
// steady state is the drag the imposed fluid absorbs).
TEST(VirialIdentity, PairVirialIsWallPlusFirstMomentOnShearCell) {
  const SceneConfig c = base_config();
  const DemParams p = dem_params(c);
  ShearCell cell = build_shear_cell(c);
  // push particles into contact with each other and the walls
  Rng rng(7);
  for (auto& x : cell.free.x) x += 1.5e-6 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
  for (auto& x : cell.free.x) x.x() = std::clamp(x.x(), -0.5 * c.gap + 1.8 * R, 0.5 * c.gap - 1.8 * R);
  DemPairLists lists = make_pair_lists(p.dipole_cutoff, 2 * R, p.skin);
  build_pair_lists(lists, cell.free, cell.walls, cell.box);
  const PairSums s = compute_dem_forces(p, cell.box, cell.free, cell.walls, lists);
  ASSERT_GT(s.max_overlap, 0.0);
  double moment = 0;
  for (std::size_t i = 0; i < cell.free.size(); ++i) moment += cell.free.x[i].x() * cell.free.f[i].z();
  const double walls = 0.5 * c.gap * (s.wall_fz[1] - s.wall_fz[0]);
  const double pairs = s.virial_mag_xz + s.virial_con_xz;
  EXPECT_NEAR(pairs, moment + walls, 1e-9 * (std::abs(moment) + std::abs(walls)));
  // and the stress form: virial = wall - first moment / V
  EXPECT_NEAR(virial_shear_stress(pairs, cell.box),
              wall_shear_stress(s.wall_fz, cell.box) - moment / cell.box.volume(),
              1e-9 * std::abs(virial_shear_stress(pairs, cell.box)));
}

}  // namespace
}  // namespace mrf
