// The backward Euler contact step of implicit_contact.hpp solved for the
// contact forces instead of the positions (the compliance or "dual" form).
//
// The step is y = b + M sum_c G_c lambda_c, M = diag(mob_i) + s C the
// displacement per unit force over the step (dt/gamma for IMEX Euler in an
// imposed flow; C, optional, couples particles through the fluid they share,
// integrate/mobility.hpp), where lambda_c >= 0 is the Hertz force of candidate pair c and G_c puts +n_c on i and -n_c on k (n_c the
// unit vector from k to i at y). The Hertz law, written as a compliance,
//   phi_c(lambda) = h_c(y(lambda)) - (lambda_c / k)^{2/3} = 0   (lambda_c > 0),
//   lambda_c = 0 and h_c(y(lambda)) <= 0                        (open),
// closes the system. Newton on (y, lambda) with y eliminated and the normals
// frozen over one linear solve: (A + C) dlambda = phi + G^T r_y on the active
// contacts (r_y: what moving the normals to the current y leaves of the
// position equation), A = G^T M G (the
// Delassus operator of the mobility, exact and linear) and C the diagonal
// compliance derivative (2/3) k^{-2/3} lambda^{-1/3}. In the position form the
// stiff Hertz law is the Jacobian, whose stiffness changes on the scale of the
// overlap itself; here the linear part dominates (A / C ~ mob k_eff,
// the stiffness ratio of the step) and the Hertz nonlinearity is a small
// correction, so Newton needs few iterations from the forces of the last step.
// The linear solves take the coupled part of M through the coupling's
// add_jacobian (possibly a cheaper approximation), the residuals through its
// add: the iteration converges to the same equations.
// Open contacts are handled by projection (lambda >= 0) with an active set;
// an update that more than doubles the largest residual is halved (down to
// 1/8 of the Newton step), and once a solve stalls the update is made
// consistent with the contacts it clips (resolve_clipped): together they
// stop the active set cycling.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "mrf/box.hpp"
#include "mrf/integrate/implicit_contact.hpp"
#include "mrf/integrate/mobility.hpp"
#include "mrf/integrate/pcg.hpp"
#include "mrf/state.hpp"

namespace mrf {

class ContactDual {
 public:
  // Solves the step for y (out), starting from the forces of the pairs at
  // positions x_start with the walls at walls_start (the last step's contact
  // forces); `walls` at the end of the step. mob: per particle (m/N);
  // coupled (or null) times coupled_scale (m kg/N) the coupled part. opt.tol
  // (m) bounds every overlap residual at convergence; opt.solver is unused.
  NewtonResult solve(const std::vector<ContactPair>& pairs, const std::vector<Vec3>& b,
                     const std::vector<Vec3>& x_start, const WallParticles& walls_start, const WallParticles& walls,
                     const Box& box, double radius, double hertz_k, const std::vector<double>& mob,
                     MobilityCoupling* coupled, double coupled_scale, const NewtonOptions& opt, std::vector<Vec3>& y);
  // Adds the contact forces of the last solve (+n lambda on i, -n lambda on
  // k) to f: pairwise opposite, so their sum over the free particles is the
  // walls' push alone, whatever the Newton tolerance.
  void add_forces(const std::vector<ContactPair>& pairs, std::vector<Vec3>& f) const;
  // The CG preconditioner. automatic: incomplete Cholesky where a product
  // is dear (a coupled mobility, whose product sweeps every DEM-SPH pair:
  // it halves the CG iterations of the coupled models), Jacobi otherwise
  // (model 1's product is cheaper than the factorisation; measured,
  // docs/performance.md).
  enum class Preconditioner { automatic, jacobi, incomplete_cholesky };
  void set_preconditioner(Preconditioner p) { precond_ = p; }

 private:
  // y += M G q over the active set, q per active contact (by_pair: per
  // candidate pair, read at act_), by the sphere index of index_spheres
  void move(const std::vector<ContactPair>& pairs, const std::vector<double>& q, bool by_pair,
            std::vector<Vec3>& y);
  // act_particles_ and, per sphere, its entries in act_ (row_start_, row_entry_)
  void index_spheres(const std::vector<ContactPair>& pairs);
  bool uses_ic0() const;  // the preconditioner of this solve
  // (A + C) p on the active set
  void apply(const std::vector<ContactPair>& pairs, const std::vector<double>& p, std::vector<double>& out);
  long solve_cg(const std::vector<ContactPair>& pairs, double rtol);
  // solve_cg without a coupled mobility and with Jacobi: the whole CG in one
  // parallel region (contact_dual_cg.cpp), d_ from zero
  long solve_cg_jacobi(double rtol, long max_it);
  // apply's parts without a coupled mobility (packed_): M G p into pdisp_ by
  // contacts, or for active spheres lo..hi by their entries; then
  // out = (A + C) p for contacts lo..hi
  void packed_scatter(const double* p);
  void packed_gather(const double* p, std::size_t lo, std::size_t hi);
  void packed_product(const double* p, double* out, std::size_t lo, std::size_t hi) const;
  // z = M^-1 r: IC(0) where solve_cg factored it, Jacobi otherwise
  void precondition(const std::vector<double>& r, std::vector<double>& z) const;
  // Once a solve has stalled (from its fourth iteration, the largest
  // residual not halved over two iterations), the Newton update is made
  // consistent where the projection would clip it: the contacts whose
  // update goes below zero force are fixed at zero and the others solved
  // again with that change on the right-hand side (pcg_fixed, from the
  // first solve's values). Without it the rest of the update assumes the
  // clipped contacts still pull, the spheres overshoot, and the solve can
  // cycle (a sphere against two nearly parallel wall spheres took turns
  // with a neighbour: docs/performance.md, session 27). Returns the CG
  // iterations.
  long resolve_clipped(const std::vector<ContactPair>& pairs, double rtol);
  // Incomplete Cholesky IC(0) of the assembled A + C on the active set,
  // the CG preconditioner. The coupled part s G^T C G enters by its
  // diagonal and by the entries of contact pairs that share a sphere when
  // one of the two is a wall contact: a wall contact's force is the one
  // the fluid does not see balanced (an interior contact's equal and
  // opposite forces meet a nearly equal response at both ends, so between
  // two interior contacts the entry is a second difference of C and is
  // left out). A
  // couples two contacts only through a sphere they share, so its graph is
  // the line graph of the contact network, and along chains (a tree of
  // contacts: cliques joined at spheres) IC(0) is close to the exact
  // factor. False (and Jacobi is used) when a pivot is not positive.
  bool factor_ic0(const std::vector<ContactPair>& pairs);
  void apply_ic0(const std::vector<double>& r, std::vector<double>& z) const;

  // Per candidate pair: force (N), compliance slope (m/N), Newton
  // right-hand side (m), unit normal (k to i; frozen over a linear solve).
  // Coupled solves: s (C_ii + C_kk - 2 C_ik) and C_ik (0 for a wall pair).
  std::vector<double> lambda_, comp_, rhs_, crel_, cik_;
  std::vector<Vec3> n_;
  std::vector<std::uint32_t> act_;           // active pairs, ascending
  std::vector<std::vector<std::uint32_t>> act_part_;  // the active pairs of each block of pairs but the first
  std::vector<std::uint32_t> act_particles_;  // the spheres of active pairs, ascending
  // Per sphere (CSR over all spheres), its entries in act_, ascending: the
  // contact's normal as G puts it on the sphere (+n at i, -n at k) and its
  // place a in act_. Every pass over the spheres (and IC(0)'s assembly)
  // reads it.
  struct SphereEntry {
    Vec3 sn;
    std::uint32_t a;
  };
  std::vector<SphereEntry> row_entry_;
  std::vector<std::uint32_t> row_start_;
  std::vector<std::vector<std::uint32_t>> row_fill_;  // index_spheres' scratch: per block of contacts, per sphere
  int sphere_blocks_ = 1;  // blocks of the passes over the spheres: 1, a pass over the contacts instead
  std::vector<double> d_, r_, diag_, dq_;           // CG on the active set: solution, right-hand side, Jacobi diagonal
  PcgScratch<double> cg_;
  std::vector<double> dot_part_;       // solve_cg_jacobi: partial sums of its dot products by chunk
  bool ic0_ready_ = false;             // solve_cg factored IC(0) for this linear solve
  std::vector<char> clipped_;          // resolve_clipped: per active contact
  std::vector<double> zero_force_;
  // The last Newton update, for a backtrack: forces, positions and normals
  // before it, its active set and its direction.
  std::vector<double> lambda_prev_, d_prev_;
  std::vector<Vec3> y_prev_, n_prev_;
  std::vector<std::uint32_t> act_prev_;
  // IC(0): the strictly lower part of L by rows (columns ascending) and its
  // diagonal.
  std::vector<std::uint32_t> l_start_, l_col_;
  std::vector<double> l_val_, l_diag_;
  mutable std::vector<double> ic_y_;
  std::vector<std::pair<std::uint32_t, double>> ic_row_;  // scratch: one row of A while it is assembled
  std::vector<Vec3> s_, y_next_, disp_;      // per particle: G q, positions with the new normals, M G q
  // Without a coupled mobility, apply reads the active pairs from a packed
  // copy made once per linear solve (normal, both mobilities, compliance
  // slope, ends; a wall pair's far end is the spare last row of pdisp_, M G q
  // of that path, with mobility 0): the same products in the same order.
  struct Packed {
    Vec3 n;
    double mob_i, mob_k, comp;
    std::uint32_t i, k;
  };
  std::vector<Packed> packed_;
  std::vector<Vec3> pdisp_;
  const std::vector<double>* mob_ = nullptr;  // of the current solve
  MobilityCoupling* coupled_ = nullptr;
  double coupled_scale_ = 0;
  Preconditioner precond_ = Preconditioner::automatic;
};

}  // namespace mrf
