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
#pragma once
#include <cstdint>
#include <vector>

#include "mrf/coupling/exchange.hpp"
#include "mrf/integrate/mobility.hpp"

namespace mrf {

class FluidResponse final : public MobilityCoupling {
 public:
  // pairs sorted by DEM index, then SPH index (coupling_pairs; throws
  // std::logic_error otherwise), the Shepard sums s_i, the
  // density rho_a that divides the SPH sums and the SPH particle mass (kg).
  void set(std::size_t n_dem, const std::vector<CouplingPair>& pairs, const std::vector<double>& s,
           const std::vector<double>& rho, double mass);
  // y_i += scale sum_j C_ij f_j for every particle i, or those in `rows`
  // (scale in the unit that turns 1/kg x f into y).
  void add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
           const std::vector<std::uint32_t>* rows = nullptr) override;
  // C_ii and C_ik (1/kg).
  double diagonal(std::size_t i) const override { return diag_[i]; }
  double coupling(std::size_t i, std::size_t k) const override;

 private:
  // Per DEM particle, per SPH neighbour (images merged): 4 x SPH index (an
  // offset into xyz padded to four doubles) and weight W / (rho_a s_j),
  // which scatters a force and, times m, gathers the response, so that an
  // application is two passes of three multiply-adds per entry.
  std::vector<std::uint32_t> a_;
  std::vector<double> scatter_;
  double mass_ = 0;
  std::vector<std::uint32_t> start_;  // pairs of DEM particle i: [start_[i], start_[i + 1])
  std::vector<std::uint32_t> rstart_, rdem_;  // the entries by SPH particle: 4 x DEM index
  std::vector<double> rscatter_;              // and scatter weight
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
