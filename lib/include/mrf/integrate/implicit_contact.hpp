// Implicit (backward Euler) solve of the stiff Hertz contacts of the
// inertialess DEM model, REFERENCE.md §2-3:
//   dx/dt = u(x) + (F_nc(x) + F_c(x)) / gamma
// with the flow u and the non-contact (dipole) force F_nc explicit and the
// contact force F_c implicit (IMEX Euler, first order):
//   G(y) = y - b - (dt/gamma) F_c(y) = 0,   b = x_n + dt (u(x_n) + F_nc(x_n)/gamma).
// Newton on G with the exact contact Jacobian J = I + (dt/gamma) K, where
// K = -dF_c/dx is assembled pair by pair from 3x3 blocks
//   K_pair = k_eff r^r^ - (f/r)(I - r^r^),   f = k h^{3/2}, k_eff = (3/2) k h^{1/2}
// (stiffness along the line of centres plus the small geometric term). K is
// symmetric, so J is symmetric and, for (dt/gamma) f/r < 1, positive definite:
// conjugate gradients apply. Wall spheres are prescribed (their positions at
// t_{n+1} are inputs), so a free-wall pair adds to the diagonal block only.
#pragma once
#include <cstdint>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/integrate/pcg.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/state.hpp"

namespace mrf {

// Linear solver of the Newton correction J d = -G.
enum class ContactLinearSolver {
  pcg,          // matrix-free conjugate gradients on the contact pairs, 3x3 block-Jacobi preconditioner
  pcg_sgs,      // the same with a symmetric block Gauss-Seidel preconditioner (sweeps along the pairs)
  eigen_cg,     // Eigen::ConjugateGradient on the assembled sparse J (diagonal preconditioner)
  eigen_ldlt,   // Eigen::SimplicialLDLT on the assembled sparse J (direct)
};
const char* to_string(ContactLinearSolver s);

// A pair that may touch during the step: free i with free k (wall = false)
// or with wall sphere k (wall = true).
struct ContactPair {
  std::uint32_t i, k;
  bool wall;
};

// Pairs of the Verlet lists closer than 2R + margin at positions x (m).
void contact_candidates(const DemPairLists& lists, const std::vector<Vec3>& x, const WallParticles& walls,
                        const Box& box, double radius, double margin, std::vector<ContactPair>& out);

// The same search in two stages. near_pairs keeps the free-free pairs of a
// Verlet list (valid at x) closer than `reach` (m) at x, sorted by (i, k) so
// that the order does not depend on when the list was built. With reach =
// 2R + margin + s it holds every pair that can come within 2R + margin until
// some particle has moved s/2. contact_candidates then filters that short
// list and the free-wall list at x.
void near_pairs(const PairRows& ff, const std::vector<Vec3>& x, const Box& box, double reach,
                std::vector<ContactPair>& out);
void contact_candidates(const std::vector<ContactPair>& ff_near, const std::vector<IndexPair>& fw,
                        const std::vector<Vec3>& x, const WallParticles& walls, const Box& box, double radius,
                        double margin, std::vector<ContactPair>& out);

// Hertz forces (N) of the candidate pairs at positions x into f (overwritten).
// Returns the largest overlap (m).
double contact_forces(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x,
                      const WallParticles& walls, const Box& box, double radius, double hertz_k,
                      std::vector<Vec3>& f);

// The 3x3 block K_pair = -dF_i/dx_i of one Hertz pair with separation r_ik
// (m), contact distance `two_r` (m); zero without overlap.
Eigen::Matrix3d hertz_stiffness_block(const Vec3& r_ik, double two_r, double hertz_k);

struct NewtonOptions {
  double tol = 0;                 // m: converged when the largest correction |d_i| is below it
  int max_iterations = 20;
  double linear_rtol = 1e-10;     // relative residual of the linear solve
  ContactLinearSolver solver = ContactLinearSolver::pcg;
};

struct NewtonResult {
  bool converged = false;
  int iterations = 0;             // Newton iterations (Jacobian solves)
  long linear_iterations = 0;     // CG iterations summed over them (1 per solve for the direct solver)
  std::uint32_t worst = 0;        // particle with the largest last correction
  double last_correction = 0;     // m
};

// Solves G(y) = 0 for y, starting from the guess in y. dt_over_gamma in s kg^-1
// (m/N per unit time). `walls` at t_{n+1}. Scratch is kept between calls.
class ContactNewton {
 public:
  NewtonResult solve(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b,
                     const WallParticles& walls, const Box& box, double radius, double hertz_k,
                     double dt_over_gamma, const NewtonOptions& opt, std::vector<Vec3>& y);

  // Phi(y) = |y - b|^2 / 2 + (dt/gamma) sum U_hertz (m^2), whose minimum the
  // backward Euler step is (grad Phi = G).
  double merit(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b, const WallParticles& walls,
               const Box& box, double radius, double hertz_k, double dt_over_gamma,
               const std::vector<Vec3>& y) const;

 private:
  struct Block {  // one touching pair at the current iterate
    std::uint32_t a, c;  // compact indices of i and k (c unused for walls)
    bool wall;
    Eigen::Matrix3d k;   // (dt/gamma) K_pair
  };
  // Forces, residual, Jacobian blocks and preconditioner at y; returns Phi(y).
  double linearise(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b, const std::vector<Vec3>& y,
                   const WallParticles& walls, const Box& box, double radius, double hertz_k, double dt_over_gamma);
  long solve_pcg(double rtol, bool sgs);
  void precondition(const std::vector<Vec3>& r, std::vector<Vec3>& z, bool sgs) const;
  long solve_eigen(ContactLinearSolver s, double rtol);
  void apply(const std::vector<Vec3>& p, std::vector<Vec3>& out) const;  // J p on the active set

  std::vector<Vec3> f_, g_;                // contact forces, residual G
  std::vector<std::int32_t> local_;        // particle -> compact index, -1 when not in contact
  std::vector<std::uint32_t> active_;      // compact -> particle
  std::vector<Block> blocks_;
  std::vector<Eigen::Matrix3d> diag_inv_;  // inverse diagonal blocks of J
  std::vector<std::uint32_t> adj_start_, adj_block_;  // free-free blocks of each active particle (CSR)
  std::vector<Vec3> rhs_, d_;                  // linear solve on the active set
  PcgScratch<Vec3> cg_;
  std::vector<Vec3> step_, trial_;             // Newton direction, line-search trial point
};

}  // namespace mrf
