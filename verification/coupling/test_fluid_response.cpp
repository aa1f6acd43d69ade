// The coupled mobility C of coupling/fluid_response.hpp against its
// definition C_ij = sum_a m W_ia W_aj / (rho_a^2 s_i s_j), formed from the
// pair list directly: the product, its symmetry, C_ii and C_ik, and the
// product restricted to some rows.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/coupling/fluid_response.hpp"

namespace mrf {
namespace {

struct Coupled {
  Box box{};
  std::vector<Vec3> dem, sph;
  std::vector<CouplingPair> pairs;
  std::vector<double> rho, s;
  double mass = 0, h = 0;
  FluidResponse response;
};

// A periodic slab (x walls at 0 and gap, y and z periodic) with SPH
// particles on a jittered lattice and DEM particles at random.
Coupled make_setup(std::size_t n_dem, unsigned seed) {
  Coupled u;
  const double gap = 60e-6, ly = 40e-6, lz = 40e-6, dx = 8e-6;
  u.box = Box{gap, ly, lz};
  u.h = 1.3 * dx;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (double x = 0; x <= gap + 1e-12; x += dx)
    for (double y = 0; y < ly - 1e-12; y += dx)
      for (double z = 0; z < lz - 1e-12; z += dx)
        u.sph.push_back(Vec3(x, y + 0.1 * dx * unit(rng), z + 0.1 * dx * unit(rng)));
  for (std::size_t i = 0; i < n_dem; ++i)
    u.dem.push_back(Vec3(gap * (0.1 + 0.8 * unit(rng)), ly * unit(rng), lz * unit(rng)));
  u.pairs = coupling_pairs(u.dem, u.sph, u.box, u.h);
  u.mass = 1000.0 * dx * dx * dx;
  u.rho.resize(u.sph.size());
  for (double& r : u.rho) r = 700.0 + 300.0 * unit(rng);  // superficial densities
  u.s.assign(n_dem, 0.0);
  for (const CouplingPair& q : u.pairs) u.s[q.i] += u.mass / u.rho[q.a] * q.w;
  u.response.set(n_dem, u.pairs, u.s, u.rho, u.mass);
  return u;
}

std::vector<Vec3> dense_product(const Coupled& u, const std::vector<Vec3>& f) {
  std::vector<Vec3> z(u.sph.size(), Vec3::Zero()), y(u.dem.size(), Vec3::Zero());
  for (const CouplingPair& q : u.pairs) z[q.a] += q.w / (u.rho[q.a] * u.s[q.i]) * f[q.i];
  for (const CouplingPair& q : u.pairs) y[q.i] += u.mass * q.w / (u.rho[q.a] * u.s[q.i]) * z[q.a];
  return y;
}

// n forces of random direction and size (N)
std::vector<Vec3> random_forces(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1e-9);
  std::vector<Vec3> f(n);
  for (auto& v : f) v = Vec3(g(rng), g(rng), g(rng));
  return f;
}

double largest(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.norm());
  return m;
}

TEST(FluidResponse, ProductMatchesTheDefinitionAndIsSymmetric) {
  Coupled u = make_setup(60, 3);
  const std::vector<Vec3> f = random_forces(u.dem.size(), 5), q = random_forces(u.dem.size(), 6);
  std::vector<Vec3> y(u.dem.size(), Vec3::Zero());
  u.response.add(f, 1.0, y);
  const std::vector<Vec3> ref = dense_product(u, f);
  for (std::size_t i = 0; i < y.size(); ++i) EXPECT_LE((y[i] - ref[i]).norm(), 1e-12 * largest(ref)) << i;
  // q . C f = f . C q, and C_ii, C_ik as the product of unit forces gives
  std::vector<Vec3> cq(u.dem.size(), Vec3::Zero());
  u.response.add(q, 1.0, cq);
  double qcf = 0, fcq = 0;
  for (std::size_t i = 0; i < y.size(); ++i) qcf += q[i].dot(y[i]), fcq += f[i].dot(cq[i]);
  EXPECT_NEAR(qcf, fcq, 1e-12 * std::abs(qcf));
  std::vector<Vec3> e(u.dem.size(), Vec3::Zero()), ce(u.dem.size(), Vec3::Zero());
  e[7] = Vec3(1, 0, 0);
  u.response.add(e, 1.0, ce);
  EXPECT_NEAR(u.response.diagonal(7), ce[7].x(), 1e-12 * ce[7].x());
  for (std::size_t k : {0u, 8u, 31u}) EXPECT_NEAR(u.response.coupling(k, 7), ce[k].x(), 1e-12 * ce[7].x()) << k;
}

// The rows variant (the contact solve reads back the spheres in contact
// only) gives those rows of the full product and leaves the others alone.
TEST(FluidResponse, RowsGiveTheRowsOfTheFullProduct) {
  Coupled u = make_setup(90, 11);
  std::mt19937 rng(13);
  std::normal_distribution<double> g(0.0, 1e-9);
  std::vector<Vec3> f(u.dem.size(), Vec3::Zero());
  for (std::size_t j = 0; j < u.dem.size(); j += 5) f[j] = Vec3(g(rng), g(rng), g(rng));
  std::vector<Vec3> full(u.dem.size(), Vec3::Zero());
  u.response.add(f, 2.5, full);
  const double scale = largest(full);
  ASSERT_GT(scale, 0.0);
  const std::vector<std::uint32_t> rows = {1, 4, 10, 44};
  std::vector<Vec3> part(u.dem.size(), Vec3::Zero());
  u.response.add(f, 2.5, part, &rows);
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (std::find(rows.begin(), rows.end(), i) != rows.end())
      EXPECT_LE((full[i] - part[i]).norm(), 1e-13 * scale) << i;
    else
      EXPECT_EQ(part[i].norm(), 0.0) << i;
  }
}

// set() builds the entries by blocks of DEM rows on threads, joined in
// order: on 1, 2 and 3 threads the diagonal, the couplings and the product
// (all rows, and some) are the same bit for bit (above the block threshold
// of 8192 pairs).
// C_J keeps the entries whose kernel value, summed over periodic images,
// reaches the bound: its product against the definition over those entries,
// symmetric like C; without a bound it is C bit for bit. With the coupled
// models' bound W(1.5 h) on a lattice of SPH particles it keeps about
// (1.5 / 2)^3 = 42 % of the entries.
TEST(FluidResponse, TheJacobianOperatorLeavesOutTheKernelRim) {
  Coupled u = make_setup(60, 3);
  const std::vector<Vec3> f = random_forces(u.dem.size(), 7), q = random_forces(u.dem.size(), 8);
  std::vector<Vec3> y(u.dem.size(), Vec3::Zero()), yj(u.dem.size(), Vec3::Zero());
  u.response.add(f, 1.0, y);
  u.response.add_jacobian(f, 1.0, yj);
  for (std::size_t i = 0; i < y.size(); ++i) ASSERT_EQ(yj[i], y[i]) << "no bound: C itself, " << i;

  const double bound = FluidResponse::jacobian_bound(u.h);
  FluidResponse r;
  r.set(u.dem.size(), u.pairs, u.s, u.rho, u.mass, bound);
  const double kept = static_cast<double>(r.jacobian_entries()) / static_cast<double>(r.entries());
  EXPECT_GT(kept, 0.30);
  EXPECT_LT(kept, 0.55);
  // the definition over the entries kept: W summed over the images of (i, a)
  std::map<std::pair<std::size_t, std::size_t>, double> w;
  for (const CouplingPair& p : u.pairs) w[{p.i, p.a}] += p.w;
  std::vector<Vec3> z(u.sph.size(), Vec3::Zero()), ref(u.dem.size(), Vec3::Zero());
  for (const auto& [ia, wia] : w)
    if (wia >= bound) z[ia.second] += wia / (u.rho[ia.second] * u.s[ia.first]) * f[ia.first];
  for (const auto& [ia, wia] : w)
    if (wia >= bound) ref[ia.first] += u.mass * wia / (u.rho[ia.second] * u.s[ia.first]) * z[ia.second];
  std::vector<Vec3> cj(u.dem.size(), Vec3::Zero());
  r.add_jacobian(f, 1.0, cj);
  for (std::size_t i = 0; i < cj.size(); ++i) EXPECT_LE((cj[i] - ref[i]).norm(), 1e-12 * largest(ref)) << i;
  // C_J differs from C, and only a little: the rim holds little weight
  double diff = 0;
  for (std::size_t i = 0; i < cj.size(); ++i) diff = std::max(diff, (cj[i] - y[i]).norm());
  EXPECT_GT(diff, 1e-6 * largest(y));
  EXPECT_LT(diff, 0.1 * largest(y));
  // symmetric: q . C_J f = f . C_J q
  std::vector<Vec3> cjq(u.dem.size(), Vec3::Zero());
  r.add_jacobian(q, 1.0, cjq);
  double qcf = 0, fcq = 0;
  for (std::size_t i = 0; i < f.size(); ++i) qcf += q[i].dot(cj[i]), fcq += f[i].dot(cjq[i]);
  EXPECT_NEAR(qcf, fcq, 1e-12 * std::abs(qcf));
  // add() is still C
  std::vector<Vec3> again(u.dem.size(), Vec3::Zero());
  r.add(f, 1.0, again);
  for (std::size_t i = 0; i < y.size(); ++i) ASSERT_EQ(again[i], y[i]) << i;
}

TEST(FluidResponse, TheSameOnAnyNumberOfThreads) {
  Coupled u = make_setup(1500, 11);
  ASSERT_GT(u.pairs.size(), 3u * 8192u);
  std::vector<Vec3> f(u.dem.size());
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = Vec3(std::sin(static_cast<double>(i)), std::cos(2.0 * static_cast<double>(i)), 0.5);
  const int saved = omp_get_max_threads();
  auto run = [&](int t) {
    omp_set_num_threads(t);
    FluidResponse r;
    r.set(u.dem.size(), u.pairs, u.s, u.rho, u.mass, FluidResponse::jacobian_bound(u.h));
    std::vector<Vec3> y(u.dem.size(), Vec3::Zero()), some(u.dem.size(), Vec3::Zero()),
        jac(u.dem.size(), Vec3::Zero());
    r.add(f, 1.0, y);
    r.add_jacobian(f, 1.0, jac);
    y.insert(y.end(), jac.begin(), jac.end());
    std::vector<std::uint32_t> rows;
    for (std::uint32_t i = 0; i < u.dem.size(); i += 3) rows.push_back(i);
    r.add(f, 0.5, some, &rows);
    y.insert(y.end(), some.begin(), some.end());
    std::vector<double> d;
    for (std::size_t i = 0; i < u.dem.size(); ++i) d.push_back(r.diagonal(i));
    for (std::size_t i = 0; i + 1 < u.dem.size(); i += 7) d.push_back(r.coupling(i, i + 1));
    return std::make_pair(y, d);
  };
  const auto one = run(1);
  for (int t : {2, 3}) {
    const auto many = run(t);
    for (std::size_t i = 0; i < one.first.size(); ++i) ASSERT_EQ(many.first[i], one.first[i]) << t << " threads, " << i;
    for (std::size_t k = 0; k < one.second.size(); ++k) ASSERT_EQ(many.second[k], one.second[k]) << t << " threads, " << k;
  }
  omp_set_num_threads(saved);
  EXPECT_GT(largest(one.first), 0.0);
}

}  // namespace
}  // namespace mrf
