// Kernels of the unresolved two-way SPH-DEM coupling (REFERENCE.md §6,
// Robinson, Ramaioli & Luding 2014): porosity at the SPH particles, Shepard
// interpolation of fluid fields at the DEM particles, and the exactly
// momentum-conserving back-reaction of the particle forces on the fluid.
// Pure functions of positions, fields and a pair list; no time integration.
//
// One pair list (DEM particle i, SPH particle a, W(r_ia, h)) serves scatter
// AND gather, so both use the same kernel and h by construction; that is what
// makes sum_a m_a a_a^c = -sum_i F_i exact (TEST 6.1). The kernel width is the
// SPH smoothing length h (Wendland C2, support 2h). SI units throughout.
//
// Density convention: `rho` is whatever density divides the SPH sums (§6: the
// superficial density rho_bar = eps rho_f in Robinson's model A). The identity
// is exact only if the SAME rho array is passed to shepard_interpolate (for
// s_i) and to add_back_coupling.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/neighbors/cell_list.hpp"

namespace mrf {

// One DEM-SPH pair within the kernel support 2h: W = W(|x_i - x_a|, h)
// (1/m^3) of the image the pair is for. 16 bytes: every pass over the pairs
// reads them, and only the inertialess step's shepard_rate needs the
// gradient, which coupling_pairs_of gives beside them when asked.
struct CouplingPair {
  std::uint32_t i;  // DEM particle
  std::uint32_t a;  // SPH particle
  double w;
};

// All DEM-SPH pairs closer than 2h (cell lists, periodic in y and z). When
// ly or lz < 4h a pair can interact through two periodic images; each image
// is then its own entry (as in SphPairs), so scatter and gather stay
// consistent in small boxes. Throws std::invalid_argument if h <= 0.
std::vector<CouplingPair> coupling_pairs(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x,
                                         const Box& box, double h);
// Same, into `out` (cleared; its capacity is reused). Pairs come sorted by
// (DEM index i, SPH index a, image), so every sum over them has the same
// order whether the pairs come from a fresh search or from candidates.
// With `grad`, also each pair's kernel gradient (coupling_pairs_of).
void coupling_pairs(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x, const Box& box, double h,
                    std::vector<CouplingPair>& out, std::vector<Vec3>* grad = nullptr);

// Verlet candidates: the (DEM i, SPH a) with a minimum-image distance below
// `reach` (m), sorted by (i, a), into `out`.
void coupling_candidates(const std::vector<Vec3>& dem_x, const std::vector<Vec3>& sph_x, const Box& box,
                         double reach, std::vector<IndexPair>& out);
// The pairs closer than 2h among the candidates, in their order (each image
// its own entry, as coupling_pairs): equal to coupling_pairs bit for bit
// when every pair within 2h is a candidate. With `grad`, also each pair's
// kernel gradient with respect to x_i, W'(r) (x_i - x_a) / r (1/m^4), of its
// image, at the same index.
void coupling_pairs_of(const std::vector<IndexPair>& candidates, const std::vector<Vec3>& dem_x,
                       const std::vector<Vec3>& sph_x, const Box& box, double h, std::vector<CouplingPair>& out,
                       std::vector<Vec3>* grad = nullptr);

// Verlet cache of the coupling pairs between two moving point sets (the DEM
// particles with their wall mirrors, the SPH fluid), rebuilt by the bound
// of neighbors/verlet_list.hpp: max|n_dem| + max|n_sph| + |gamma| reach <=
// skin (non-affine displacements n since the build, gamma the imposed
// strain since the build; the caller adds gdot dt). The pairs do not depend
// on when the candidates were built (coupling_pairs_of), so a checkpoint
// need not hold the cache: a loaded run rebuilds it and finds the same pairs.
struct CouplingPairCache {
  double skin = 0;  // m; 0 = search every time
  std::vector<IndexPair> candidates;
  std::vector<Vec3> dem_ref, sph_ref;  // positions at the build
  double strain = 0;
  long builds = 0;
};

// True when the candidates may miss a pair within 2h (or were never built,
// or the number of points changed).
bool coupling_cache_stale(const CouplingPairCache& cache, const std::vector<Vec3>& dem_x,
                          const std::vector<Vec3>& sph_x, const Box& box, double h);
// Builds the candidates at the current positions.
void rebuild_coupling_cache(CouplingPairCache& cache, const std::vector<Vec3>& dem_x,
                            const std::vector<Vec3>& sph_x, const Box& box, double h);

// Default porosity floor: eps below it (overlapping kernels of a dense packing)
// would make the drag and eps-weighted densities blow up; 0.2 is well below
// random close packing (eps ~ 0.36), so a physical packing is not clamped.
inline constexpr double k_porosity_floor = 0.2;

struct PorosityField {
  std::vector<double> eps;  // per SPH particle, in [floor, 1] (1)
  std::size_t clamped = 0;  // how many were raised to the floor
};

// eps_a = max(floor, 1 - sum_i V_p W(r_ai, h)); V_p the DEM particle volume
// (all particles of one species, m^3).
PorosityField porosity_at_fluid(std::size_t n_sph, double particle_volume, const std::vector<CouplingPair>& pairs,
                                double floor = k_porosity_floor);

struct ShepardField {
  std::vector<double> s;    // s_i = sum_a (m/rho_a) W_ia (1)
  std::vector<Vec3> u;      // u_i = sum_a (m/rho_a) W_ia v_a / s_i (m/s)
  std::vector<double> eps;  // eps_i, same weights (1)
};

// Shepard interpolation at the n_dem DEM particles from SPH particles of mass
// `mass` (kg), density rho (kg/m^3), velocity v and porosity eps. Throws
// NumericalError naming the first DEM particle with s_i = 0 (no SPH
// neighbour within 2h).
ShepardField shepard_interpolate(std::size_t n_dem, const std::vector<CouplingPair>& pairs, double mass,
                                 const std::vector<double>& rho, const std::vector<Vec3>& v,
                                 const std::vector<double>& eps);

// How fast the Shepard interpolant u_i = sum_a (m/rho_a) W(x_i - x_a) v_a / s_i
// changes at DEM particle i moving at c_i while the SPH particles move at
// their velocities v_a (v_a and rho_a held): the exact time derivative
//   du_i/dt = sum_a (m/rho_a) (v_a - u_i) (dw_ia . (c_i - v_a)) / s_i   (m/s^2),
// with s and u from shepard_interpolate on the same pairs, mass, rho and v,
// and dw the pairs' kernel gradients (coupling_pairs_of's `grad`).
// In a smooth flow it is (c_i - u_i) . grad u; it also holds the flicker of
// the interpolant as the SPH particles stream past.
std::vector<Vec3> shepard_rate(const std::vector<CouplingPair>& pairs, const std::vector<Vec3>& dw, double mass,
                               const std::vector<double>& rho, const std::vector<Vec3>& v, const ShepardField& at,
                               const std::vector<Vec3>& c);

// Generalised buoyancy of the averaged equations (model A, REFERENCE §6):
//   F_i = V_p (-grad p + div tau)_i = V_p sum_a (m/rho_a) W_ia (rho_a a_a) / s_i,
// with a_a the SPH pressure + viscous acceleration of fluid particle a (m/s^2,
// no body force, no coupling). The SPH sums divided by rho_a give
// (-grad p + div tau)/rho_a, so rho_a a_a is the mixture's force density
// whatever rho is (superficial or not): the buoyancy is V_p grad p, not
// V_p grad p / eps (Robinson's rho_f form with superficial rho) and not 0
// (model B). particle_volume V_p in m^3; returns N.
std::vector<Vec3> generalised_buoyancy(std::size_t n_dem, const std::vector<CouplingPair>& pairs, double mass,
                                       const std::vector<double>& s, const std::vector<Vec3>& a_fluid,
                                       double particle_volume);

// Back-reaction of the fluid-to-particle forces F_i (N) on the SPH particles:
//   a_out[a] += -(1/rho_a) sum_i F_i W_ia / s_i   (m/s^2),
// accumulated (e.g. into FluidParticles::a_ext). With s from
// shepard_interpolate on the same pairs, mass and rho:
//   sum_a mass a_a^c = -sum_i F_i   to round-off.
void add_back_coupling(const std::vector<CouplingPair>& pairs, const std::vector<Vec3>& force,
                       const std::vector<double>& s, const std::vector<double>& rho, std::vector<Vec3>& a_out);

}  // namespace mrf
