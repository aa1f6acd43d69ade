// How the fluid velocity at the DEM particles responds to impulses the
// particles give the fluid (REFERENCE.md §6), for the implicit coupled step.
//
// An impulse P_j that particle j gives the fluid is scattered to the SPH
// particles as dv_a = W_aj P_j / (rho_a s_j) (add_back_coupling, exactly
// momentum conserving), and the fluid velocity at particle i is gathered
// back with the Shepard weights (m/rho_a) W_ia / s_i. Together:
//   du_i = sum_j C_ij P_j,   C_ij = sum_a m W_ia W_aj / (rho_a^2 s_i s_j)  (1/kg).
// C is symmetric positive semi-definite (C = B^T B, B_aj = sqrt(m) W_aj /
// (rho_a s_j)); its row sum is the inverse collective inertia 1/M_i of the
// inertial scheme (coupled_model.cpp), exact for a uniform suspension. Two
// particles in the same kernel share their fluid (C_ik ~ C_ii), so C moves
// them together and leaves their relative motion to the drag alone: what a
// per-particle parcel inertia would get wrong.
//
// The contact solve's Newton iterations (integrate/contact_dual.hpp) apply C
// in every CG iteration of their linear solves, the largest cost of a
// coupled step. Their Jacobian may take a cheaper C_J: C without the
// entries whose kernel value W_ia is below a bound, the far rim of the
// kernel (with W(1.5 h) as the bound, 57 % of the entries, 2.2 % of a
// uniform kernel's weight and 0.05 % of W^2's). The Newton residual is
// always taken with C, so the solve stops at the same tolerance on the same
// equations; only its convergence rate could change (docs/coupled-models.md).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/integrate/mobility.hpp"

namespace mrf {

class FluidResponse final : public MobilityCoupling {
 public:
  // The bound of C_J that the coupled models use: W(k_jacobian_q h) for the
  // smoothing length h (m), in 1/m^3.
  static constexpr double k_jacobian_q = 1.5;
  static double jacobian_bound(double h);
  // pairs sorted by DEM index, then SPH index (coupling_pairs; throws
  // std::logic_error otherwise), the Shepard sums s_i, the
  // density rho_a that divides the SPH sums and the SPH particle mass (kg).
  // With w_jacobian_min > 0, add_jacobian leaves out the entries whose
  // kernel value (over all periodic images, 1/m^3) is below it.
  void set(std::size_t n_dem, const std::vector<CouplingPair>& pairs, const std::vector<double>& s,
           const std::vector<double>& rho, double mass, double w_jacobian_min = 0.0);
  // y_i += scale sum_j C_ij f_j for every particle i, or those in `rows`
  // (scale in the unit that turns 1/kg x f into y).
  void add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
           const std::vector<std::uint32_t>* rows = nullptr) override;
  // The same with C_J (the header comment); C itself without a bound.
  void add_jacobian(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                    const std::vector<std::uint32_t>* rows = nullptr) override;
  // The entries of C and of C_J, per DEM particle: what a product reads.
  std::size_t entries() const { return exact_.by_dem.col.size(); }
  std::size_t jacobian_entries() const { return (jacobian_ ? *jacobian_ : exact_).by_dem.col.size(); }
  // C_ii and C_ik (1/kg).
  double diagonal(std::size_t i) const override { return diag_[i]; }
  double coupling(std::size_t i, std::size_t k) const override;

 private:
  // Entries of one direction: row r's in [start[r], start[r + 1]), each an
  // offset into xyz padded to four doubles (4 x column index) and the weight
  // W / (rho_a s_j), which scatters a force and, times m, gathers the
  // response, so that an application is two passes of three multiply-adds
  // per entry.
  struct Csr {
    std::vector<std::uint32_t> start, col;
    std::vector<double> w;
  };
  // An operator's entries per DEM particle (per SPH neighbour, images
  // merged) and the same per SPH particle (in ascending DEM order).
  struct Entries {
    Csr by_dem, by_sph;
  };
  Entries exact_;
  std::optional<Entries> jacobian_;  // C_J, when it leaves entries out
  double mass_ = 0;
  // by_sph from by_dem (column indices, not yet offsets) on the blocks of
  // DEM rows of set(); then both index lists become offsets
  void index_by_sph(Entries& e, std::size_t na, int blocks);
  void product(const Entries& e, const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
               const std::vector<std::uint32_t>* rows);
  std::vector<std::vector<std::uint32_t>> fill_;  // scratch of set(): per block of rows, its next free slot per SPH particle
  std::vector<std::vector<std::uint32_t>> part_a_;  // scratch of set(): the entries of each block of rows but the first
  std::vector<std::vector<double>> part_scatter_;
  // Threads only where there is work for them (a parallel region costs a
  // few microseconds); the choice depends on the pairs alone.
  static constexpr std::size_t k_entries_per_thread = 20000;
  std::vector<double> diag_;
  // scratch of add(), xyz padded to four doubles: the forces, per SPH
  // particle sum_j W_aj f_j / (rho_a s_j), and the gathered response
  std::vector<double> f4_, z4_, y4_;
  mutable std::vector<double> dense_; // scratch of coupling(): at 4 x SPH index, zero between calls
};

}  // namespace mrf
