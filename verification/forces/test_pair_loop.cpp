// The law that is tested is the law that runs (STYLE.md §4): on random
// shear-cell configurations with many contacts, the forces, virials and
// energies of compute_dem_forces equal a brute-force O(N^2) minimum-image sum
// of the forces/ laws pair by pair, to round-off: dipole_force and
// dipole_energy with general moments (REFERENCE.md Eq. 3, an implementation
// independent of the DipoleX evaluator the loop runs) and hertz_pair_force,
// hertz_energy (Eq. 2). The same loop run with a sign-flipped evaluator fails
// the same check by many orders of magnitude.
#include <gtest/gtest.h>
#include <hwy/targets.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <tuple>

#include "mrf/forces/dipole.hpp"
#include "mrf/forces/hertz.hpp"
#include "mrf/quasistatic/shifted_dipole.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {
namespace {

constexpr double R = 2.5e-6;
constexpr double k_tol = 1e-12;  // relative, round-off

struct Case {
  SceneConfig c;
  DemParams p;
  ShearCell cell;
  DemPairLists lists;
};

// About 330 spheres, dipole cut-off 4 d (the paper's), pushed into contact
// with each other and, stretched in x, with the walls (as test_stress.cpp).
Case random_case(std::uint64_t seed, double magnetization, bool walls = true, double cutoff = 8 * R) {
  Case s;
  s.c.radius = R;
  s.c.density = 7800;
  s.c.magnetization = magnetization;
  s.c.youngs_modulus = 200e9;
  s.c.poisson_ratio = 0.3;
  s.c.viscosity = 0.1;
  s.c.dipole_cutoff = cutoff;
  s.c.wall_spacing = R;
  s.c.gap = 44e-6;
  s.c.ly = s.c.lz = 44e-6;  // cut-off + skin < l/2: one image per pair
  s.c.volume_fraction = 0.25;
  s.c.shear_rate = 1e3;
  s.c.seed = seed;
  s.p = dem_params(s.c);
  s.cell = build_shear_cell(s.c);
  Rng rng(seed + 100);
  for (auto& x : s.cell.free.x) {
    x += 1.5e-6 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    x.x() = std::clamp(1.1 * x.x(), -0.5 * s.c.gap + 1.8 * R, 0.5 * s.c.gap - 1.8 * R);  // onto the walls
    s.cell.box.wrap(x);
  }
  if (!walls) s.cell.walls = WallParticles{};
  s.lists = make_pair_lists(std::max(cutoff, 2 * R), walls ? 2 * R : 0.0, s.p.skin);  // as DemModel
  build_pair_lists(s.lists, s.cell.free, s.cell.walls, s.cell.box);
  return s;
}

// Pair-by-pair sums of the laws, and beside each the scale its round-off is
// measured against: the sum of |terms|, where a contact term also carries
// k_eff r = (3/2) k h^{1/2} r, the change of |F| per relative change of r
// (h = 2R - r loses digits when h << r, in the loop as in any evaluation).
struct Reference {
  std::vector<Vec3> f;
  std::vector<double> f_scale;
  PairSums s, scale;
  int ff_contacts = 0, fw_contacts = 0;
};

Reference brute_force(const Case& s) {
  const DemParams& p = s.p;
  const Box& box = s.cell.box;
  const auto& x = s.cell.free.x;
  const Vec3 m(p.moment, 0, 0);
  const std::size_t n = x.size();
  Reference ref;
  ref.f.assign(n, Vec3::Zero());
  ref.f_scale.assign(n, 0.0);
  // Hertz term of one pair, shared by free-free and free-wall pairs.
  auto contact = [&](const Vec3& r_ik, Vec3& f, double& f_cond) {
    const double h = 2 * R - r_ik.norm();
    if (h <= 0) return false;
    f = hertz_pair_force(r_ik, 2 * R, p.hertz_k);
    f_cond = f.norm() + hertz_local_stiffness(h, p.hertz_k) * r_ik.norm();
    ref.s.virial_con_xz += r_ik.x() * f.z();
    ref.scale.virial_con_xz += std::abs(r_ik.x()) * f_cond;
    ref.s.energy_hertz += hertz_energy(h, p.hertz_k);
    ref.scale.energy_hertz += hertz_energy(h, p.hertz_k) + f.norm() * r_ik.norm();
    ref.s.max_overlap = std::max(ref.s.max_overlap, h);
    return true;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = i + 1; k < n; ++k) {
      const Vec3 r_ik = box.min_image(x[i] - x[k]);
      Vec3 f = Vec3::Zero();
      double scale = 0;
      if (p.dipole_pref > 0 && r_ik.squaredNorm() < p.dipole_cutoff * p.dipole_cutoff) {
        f = dipole_force(r_ik, m, m);
        scale = f.norm();
        ref.s.virial_mag_xz += r_ik.x() * f.z();
        ref.scale.virial_mag_xz += std::abs(r_ik.x() * f.z());
        ref.s.energy_dipole += dipole_energy(r_ik, m, m);
        ref.scale.energy_dipole += std::abs(dipole_energy(r_ik, m, m));
      }
      Vec3 fc;
      double cond;
      if (contact(r_ik, fc, cond)) {
        f += fc;
        scale += cond;
        ++ref.ff_contacts;
      }
      ref.f[i] += f;
      ref.f[k] -= f;
      ref.f_scale[i] += scale;
      ref.f_scale[k] += scale;
    }
  const WallParticles& w = s.cell.walls;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < w.size(); ++k) {
      Vec3 fc;
      double cond;
      if (!contact(box.min_image(x[i] - w.x[k]), fc, cond)) continue;
      ref.f[i] += fc;
      ref.f_scale[i] += cond;
      ref.s.wall_fz[w.side[k] > 0 ? 1 : 0] -= fc.z();
      ref.scale.wall_fz[w.side[k] > 0 ? 1 : 0] += cond;
      ++ref.fw_contacts;
    }
  return ref;
}

// The check: largest deviation of the loop's forces from the reference, in
// units of each particle's round-off scale.
double max_force_deviation(const std::vector<Vec3>& f, const Reference& ref) {
  double worst = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double d = (f[i] - ref.f[i]).norm();
    worst = std::max(worst, ref.f_scale[i] > 0 ? d / ref.f_scale[i] : (d > 0 ? 1.0 : 0.0));
  }
  return worst;
}

double rel(double a, double b, double scale) { return scale > 0 ? std::abs(a - b) / scale : std::abs(a - b); }

// OpenMP thread count for one scope.
struct Threads {
  int before = omp_get_max_threads();
  explicit Threads(int n) { omp_set_num_threads(n); }
  ~Threads() { omp_set_num_threads(before); }
};

template <class Laws>
PairSums run_loop(const Laws& laws, Case& s, int threads) {
  const Threads scope(threads);
  ForceBuffers buf;
  return compute_pair_forces(laws, s.cell.box, s.cell.free, s.cell.walls, s.lists, buf);
}

// The check on one configuration: loop against the pair-by-pair laws.
void expect_loop_matches_laws(Case& s, int threads) {
  const Reference ref = brute_force(s);
  ASSERT_GT(ref.ff_contacts, 20);  // the configuration exercises both laws
  ASSERT_GT(ref.fw_contacts, 10);
  const PairSums got = run_loop(dem_pair_laws(s.p), s, threads);
  {  // compute_dem_forces, what the models call, is this loop with these laws: same bits
    const Threads scope(threads);
    FreeParticles again = s.cell.free;
    const PairSums sums = compute_dem_forces(s.p, s.cell.box, again, s.cell.walls, s.lists);
    EXPECT_EQ(again.f, s.cell.free.f);
    EXPECT_EQ(sums.virial_mag_xz + sums.virial_con_xz, got.virial_mag_xz + got.virial_con_xz);
  }
  EXPECT_LT(max_force_deviation(s.cell.free.f, ref), k_tol);
  EXPECT_LT(rel(got.virial_mag_xz, ref.s.virial_mag_xz, ref.scale.virial_mag_xz), k_tol);
  EXPECT_LT(rel(got.virial_con_xz, ref.s.virial_con_xz, ref.scale.virial_con_xz), k_tol);
  EXPECT_LT(rel(got.energy_dipole, ref.s.energy_dipole, ref.scale.energy_dipole), k_tol);
  EXPECT_LT(rel(got.energy_hertz, ref.s.energy_hertz, ref.scale.energy_hertz), k_tol);
  for (int w : {0, 1}) EXPECT_LT(rel(got.wall_fz[w], ref.s.wall_fz[w], ref.scale.wall_fz[w]), k_tol);
  EXPECT_NEAR(got.max_overlap, ref.s.max_overlap, k_tol * R);
  if (s.p.dipole_pref == 0) {
    EXPECT_EQ(got.virial_mag_xz, 0.0);
    EXPECT_EQ(got.energy_dipole, 0.0);
  }
}

// (seed, magnetization A/m, threads): the magnetic and the contact-only loop,
// serial and with the per-thread buffers.
class PairLoopMatchesLaws : public ::testing::TestWithParam<std::tuple<int, double, int>> {};

TEST_P(PairLoopMatchesLaws, ForcesVirialsAndEnergies) {
  const auto [seed, magnetization, threads] = GetParam();
  Case s = random_case(static_cast<std::uint64_t>(seed), magnetization);
  ASSERT_GE(s.lists.ff.size() + s.lists.fw.size(), 2 * 4096u);  // enough pairs for 2 threads
  expect_loop_matches_laws(s, threads);
}

INSTANTIATE_TEST_SUITE_P(RandomShearCells, PairLoopMatchesLaws,
                         ::testing::Combine(::testing::Values(1, 2, 3), ::testing::Values(1e6, 0.0),
                                            ::testing::Values(1, 2)));

// Two threads asked and a team of one given (OpenMP may give fewer threads
// than asked: OMP_DYNAMIC, OMP_THREAD_LIMIT, a call inside another region):
// the one thread takes every row, and the forces are the serial loop's.
TEST(PairLoop, ATeamSmallerThanAskedGivesTheSerialForces) {
  Case serial = random_case(4, 1e6), team_of_one = serial;
  const PairSums a = run_loop(dem_pair_laws(serial.p), serial, 1);
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(0);  // every team of one thread
  const PairSums b = run_loop(dem_pair_laws(team_of_one.p), team_of_one, 2);
  omp_set_max_active_levels(levels);
  EXPECT_EQ(serial.cell.free.f, team_of_one.cell.free.f);
  EXPECT_EQ(a.virial_mag_xz, b.virial_mag_xz);
  EXPECT_EQ(a.energy_hertz, b.energy_hertz);
}

// A dipole cut-off inside the contact distance (scene input refuses it; the
// loop still tests every pair against it then).
TEST(PairLoop, DipoleCutoffInsideContactDistance) {
  Case s = random_case(6, 1e6, true, 1.5 * R);
  expect_loop_matches_laws(s, 1);
}

// Newton's third law through the loop: among free particles alone the forces
// cancel; with walls the net z-force on the particles is minus the wall forces.
TEST(PairLoop, NewtonsThirdLawAmongFreeParticles) {
  for (int threads : {1, 2}) {
    Case s = random_case(4, 1e6, false);
    const PairSums sums = run_loop(dem_pair_laws(s.p), s, threads);
    ASSERT_GT(sums.max_overlap, 0.0);
    Vec3 total = Vec3::Zero();
    double scale = 0;
    for (const Vec3& f : s.cell.free.f) {
      total += f;
      scale += f.norm();
    }
    EXPECT_LT(total.norm(), k_tol * scale) << threads << " threads";
  }
  Case s = random_case(4, 1e6, true);
  const PairSums sums = run_loop(dem_pair_laws(s.p), s, 1);
  double fz = 0, scale = 0;
  for (const Vec3& f : s.cell.free.f) {
    fz += f.z();
    scale += f.norm();
  }
  EXPECT_NEAR(fz, -(sums.wall_fz[0] + sums.wall_fz[1]), k_tol * scale);
}

// Deliberately wrong evaluators: the same loop running them must fail the
// check above by far more than its tolerance.
struct FlippedHertz : HertzPair {
  bool eval(double r2, double inv_r, HertzContact& c) const {
    if (!HertzPair::eval(r2, inv_r, c)) return false;
    c.f_over_r = -c.f_over_r;  // attraction on overlap
    return true;
  }
};
struct FlippedDipole : DipoleX {
  double eval(double dx, double dy, double dz, double inv_r, Vec3& f) const {
    const double u = DipoleX::eval(dx, dy, dz, inv_r, f);
    f = -f;
    return u;
  }
};

TEST(PairLoop, FlippedSignEvaluatorFailsTheCheck) {
  Case s = random_case(5, 1e6);
  const Reference ref = brute_force(s);
  const DemPairLaws<> right = dem_pair_laws(s.p);

  run_loop(right, s, 1);
  EXPECT_LT(max_force_deviation(s.cell.free.f, ref), k_tol);

  const DemPairLaws<DipoleX, FlippedHertz> bad_contact{right.dipole, FlippedHertz{right.contact},
                                                       right.dipole_cutoff, right.magnetic};
  const PairSums sc = run_loop(bad_contact, s, 1);
  EXPECT_GT(max_force_deviation(s.cell.free.f, ref), 1e6 * k_tol);
  EXPECT_GT(rel(sc.virial_con_xz, ref.s.virial_con_xz, ref.scale.virial_con_xz), 1e6 * k_tol);

  const DemPairLaws<FlippedDipole, HertzPair> bad_dipole{FlippedDipole{right.dipole}, right.contact,
                                                         right.dipole_cutoff, right.magnetic};
  const PairSums sd = run_loop(bad_dipole, s, 1);
  EXPECT_GT(max_force_deviation(s.cell.free.f, ref), 1e6 * k_tol);
  EXPECT_GT(rel(sd.virial_mag_xz, ref.s.virial_mag_xz, ref.scale.virial_mag_xz), 1e6 * k_tol);
}

// The kernel's own loads and stores (AVX2: one 4-wide load and store per
// partner in the padded copies) against the scalar loop on a list of every
// pair in range, each row in descending order: partners that are
// neighbours in memory share a vector in most rows, k + 1 before k, so a
// lane whose store overlapped its neighbour's would lose that update (a
// whole pair force, not round-off); and the last sphere, next to the
// padded copies' far dummy that fills a row's last vector, is a partner in
// many rows.
TEST(PairLoop, VectorKernelWithNeighbouringPartnersEqualsTheScalarLoop) {
  Case s = random_case(5, 1e6, false);
  const std::size_t n = s.cell.free.size();
  const double reach = std::max(s.p.dipole_cutoff, 2 * R);
  PairRows rows;
  rows.start.push_back(0);
  std::size_t adjacent = 0, last = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = n - 1; k > i; --k) {
      if (s.cell.box.min_image(s.cell.free.x[i] - s.cell.free.x[k]).norm() >= reach) continue;
      if (rows.start.back() < rows.k.size() && rows.k.back() == k + 1) ++adjacent;
      if (k == n - 1) ++last;
      rows.k.push_back(static_cast<std::uint32_t>(k));
    }
    rows.start.push_back(static_cast<std::uint32_t>(rows.k.size()));
  }
  ASSERT_GT(adjacent, 100u);
  ASSERT_GT(last, 10u);
  const Reference ref = brute_force(s);  // the same pairs: every one in range
  const DemPairLaws<> laws = dem_pair_laws(s.p);
  std::vector<Vec3> f_scalar(n, Vec3::Zero()), f_vector(n, Vec3::Zero());
  PairSums scalar, vector;
  detail::free_rows<true, false>(laws, s.cell.box, s.cell.free.x, rows, 0, n, f_scalar, scalar);
  detail::free_rows_simd(laws, s.cell.box, s.cell.free.x, rows, 0, n, f_vector, vector);
  double worst = 0;
  for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, (f_vector[i] - f_scalar[i]).norm() / ref.f_scale[i]);
  EXPECT_LT(worst, 1e-14);
  EXPECT_LT(rel(vector.energy_dipole, scalar.energy_dipole, ref.scale.energy_dipole), 1e-14);
}

// The vectorised kernel (scene/pair_kernel_simd.cpp, Highway, the best
// instruction set of this machine) against the scalar loop free_rows on the
// same rows: each pair's force is the same expression but for 1/r (a refined
// rsqrt14 on AVX-512, sqrt(r^2) * (1/r^2) elsewhere: a few ulp off), and the row sums run in another order,
// so forces and sums agree to round-off; the overlap is a maximum of values
// that differ by a few ulp. The configurations have
// rows of every length, so both the vector body and the scalar tail run.
TEST(PairLoop, VectorKernelEqualsTheScalarLoop) {
  std::printf("pair kernel target: %s\n", pair_kernel_target());
  for (std::uint64_t seed : {3u, 8u}) {
    Case s = random_case(seed, 1e6, false);
    const Reference ref = brute_force(s);
    ASSERT_GT(ref.ff_contacts, 20);
    const DemPairLaws<> laws = dem_pair_laws(s.p);
    const std::size_t n = s.cell.free.size(), rows = s.lists.ff.rows();
    std::vector<Vec3> f_scalar(n, Vec3::Zero()), f_vector(n, Vec3::Zero());
    PairSums scalar, vector;
    detail::free_rows<true, false>(laws, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, f_scalar, scalar);
    detail::free_rows_simd(laws, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, f_vector, vector);
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, (f_vector[i] - f_scalar[i]).norm() / ref.f_scale[i]);
    EXPECT_LT(worst, 1e-14);
    EXPECT_LT(rel(vector.virial_mag_xz, scalar.virial_mag_xz, ref.scale.virial_mag_xz), 1e-14);
    EXPECT_LT(rel(vector.virial_con_xz, scalar.virial_con_xz, ref.scale.virial_con_xz), 1e-14);
    EXPECT_LT(rel(vector.energy_dipole, scalar.energy_dipole, ref.scale.energy_dipole), 1e-14);
    EXPECT_LT(rel(vector.energy_hertz, scalar.energy_hertz, ref.scale.energy_hertz), 1e-14);
    EXPECT_NEAR(vector.max_overlap, scalar.max_overlap, 1e-12 * R);
    EXPECT_GT(vector.max_overlap, 0.0);
    // the quasi-static driver's shifted-force dipole runs the same kernel
    const DemPairLaws<DipoleXShiftedForce, HertzPair> shifted{shifted_dipole_x(s.p.dipole_pref, s.p.dipole_cutoff),
                                                              laws.contact, laws.dipole_cutoff, true};
    std::vector<Vec3> g_scalar(n, Vec3::Zero()), g_vector(n, Vec3::Zero());
    PairSums sh_scalar, sh_vector;
    detail::free_rows<true, false>(shifted, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, g_scalar, sh_scalar);
    detail::free_rows_simd_shifted(shifted, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, g_vector, sh_vector);
    double worst_shifted = 0, differs = 0;
    for (std::size_t i = 0; i < n; ++i) {
      worst_shifted = std::max(worst_shifted, (g_vector[i] - g_scalar[i]).norm() / ref.f_scale[i]);
      differs = std::max(differs, (g_scalar[i] - f_scalar[i]).norm() / ref.f_scale[i]);
    }
    EXPECT_LT(worst_shifted, 1e-14);
    EXPECT_GT(differs, 1e-6);  // the shift is seen: not the plain law by mistake
    EXPECT_LT(rel(sh_vector.energy_dipole, sh_scalar.energy_dipole, ref.scale.energy_dipole), 1e-14);
    EXPECT_LT(rel(sh_vector.virial_mag_xz, sh_scalar.virial_mag_xz, ref.scale.virial_mag_xz), 1e-14);
    // and a force that is wrong by one pair's contact is seen
    std::vector<Vec3> f_missing = f_vector;
    f_missing[s.lists.ff.k[0]] += hertz_pair_force(Vec3(2 * R - 1e-8, 0, 0), 2 * R, s.p.hertz_k);
    double moved = 0;
    for (std::size_t i = 0; i < n; ++i) moved = std::max(moved, (f_missing[i] - f_scalar[i]).norm() / ref.f_scale[i]);
    EXPECT_GT(moved, 1e-6);
  }
}

// Every instruction set the kernel was compiled for that this machine runs
// (here AVX2, SSE4, SSSE3; AVX-512 where the CPU has it), chosen in turn
// through Highway's test mock: each has its own loads, stores, 1/r and
// masks, and only the best one runs in a scene.
TEST(PairLoop, EveryCompiledTargetOfTheVectorKernelEqualsTheScalarLoop) {
  Case s = random_case(3, 1e6, false);
  const Reference ref = brute_force(s);
  const DemPairLaws<> laws = dem_pair_laws(s.p);
  const std::size_t n = s.cell.free.size(), rows = s.lists.ff.rows();
  std::vector<Vec3> f_scalar(n, Vec3::Zero());
  PairSums scalar;
  detail::free_rows<true, false>(laws, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, f_scalar, scalar);
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  EXPECT_GE(targets.size(), 2u);
  for (const int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    EXPECT_STREQ(pair_kernel_target(), hwy::TargetName(target));
    std::printf("pair kernel target: %s\n", pair_kernel_target());
    std::vector<Vec3> f_vector(n, Vec3::Zero());
    PairSums vector;
    detail::free_rows_simd(laws, s.cell.box, s.cell.free.x, s.lists.ff, 0, rows, f_vector, vector);
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, (f_vector[i] - f_scalar[i]).norm() / ref.f_scale[i]);
    EXPECT_LT(worst, 1e-14) << hwy::TargetName(target);
    EXPECT_LT(rel(vector.energy_dipole, scalar.energy_dipole, ref.scale.energy_dipole), 1e-14) << hwy::TargetName(target);
    EXPECT_LT(rel(vector.virial_mag_xz, scalar.virial_mag_xz, ref.scale.virial_mag_xz), 1e-14) << hwy::TargetName(target);
    EXPECT_NEAR(vector.max_overlap, scalar.max_overlap, 1e-12 * R) << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);  // back to the best target
}

}  // namespace
}  // namespace mrf
