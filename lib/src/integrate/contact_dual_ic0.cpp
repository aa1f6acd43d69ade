// The contact solve's CG preconditioner (integrate/contact_dual.hpp):
// incomplete Cholesky IC(0) of the assembled operator on the active
// contacts, or Jacobi where IC(0) is not used or its factorisation fails.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "mrf/integrate/contact_dual.hpp"

namespace mrf {

void ContactDual::precondition(const std::vector<double>& r, std::vector<double>& z) const {
  if (ic0_ready_) {
    apply_ic0(r, z);
    return;
  }
  z.resize(r.size());
  for (std::size_t a = 0; a < r.size(); ++a) z[a] = r[a] / diag_[a];
}

bool ContactDual::factor_ic0(const std::vector<ContactPair>& pairs) {
  const std::vector<double>& mob = *mob_;
  const std::size_t m = act_.size();
  // Row a of A below the diagonal: b < a sharing a sphere p, entry
  // s_a s_b mob_p n_a . n_b (s = +1 on i, -1 on k). Two contacts share at
  // most one sphere, so no entry is found twice; rows come out ascending
  // because each sphere's list is.
  l_start_.assign(m + 1, 0);
  l_col_.clear();
  l_val_.clear();
  std::vector<std::pair<std::uint32_t, double>>& row = ic_row_;
  for (std::size_t a = 0; a < m; ++a) {
    const ContactPair& c = pairs[act_[a]];
    const Vec3& na = n_[act_[a]];
    row.clear();
    for (int end = 0; end < (c.wall ? 1 : 2); ++end) {
      const std::uint32_t p = end == 0 ? c.i : c.k;
      const double sa = end == 0 ? 1.0 : -1.0;
      for (std::uint32_t e = row_start_[p]; e < row_start_[p + 1]; ++e) {  // index_spheres
        const std::uint32_t b = row_entry_[e].a;
        if (b >= a) break;
        const ContactPair& cb = pairs[act_[b]];
        const double sb = cb.i == p ? 1.0 : -1.0;
        double v = mob[p];
        if (coupled_ && (c.wall || cb.wall))  // s (C_pp - C_p,k(a) - C_p,k(b)), the far ends' term absent
          v += coupled_scale_ * (coupled_->diagonal(p) - cik_[act_[a]] - cik_[act_[b]]);
        row.emplace_back(b, sa * sb * v * na.dot(n_[act_[b]]));
      }
    }
    std::sort(row.begin(), row.end());
    for (const auto& [b, v] : row) {
      l_col_.push_back(b);
      l_val_.push_back(v);
    }
    l_start_[a + 1] = static_cast<std::uint32_t>(l_col_.size());
  }
  // IC(0) by rows: L_ab = (A_ab - sum_{j < b} L_aj L_bj) / L_bb over the
  // pattern of A, L_aa = sqrt(A_aa - sum_b L_ab^2).
  l_diag_.resize(m);
  for (std::size_t a = 0; a < m; ++a) {
    double d = diag_[a];
    for (std::uint32_t e = l_start_[a]; e < l_start_[a + 1]; ++e) {
      const std::uint32_t b = l_col_[e];
      double v = l_val_[e];
      // the dot product of row a (entries before e) with row b
      std::uint32_t p = l_start_[a], q = l_start_[b];
      while (p < e && q < l_start_[b + 1]) {
        if (l_col_[p] < l_col_[q]) {
          ++p;
        } else if (l_col_[q] < l_col_[p]) {
          ++q;
        } else {
          v -= l_val_[p++] * l_val_[q++];
        }
      }
      l_val_[e] = v / l_diag_[b];
      d -= l_val_[e] * l_val_[e];
    }
    if (!(d > 1e-12 * diag_[a])) return false;
    l_diag_[a] = std::sqrt(d);
  }
  return true;
}

void ContactDual::apply_ic0(const std::vector<double>& r, std::vector<double>& z) const {
  const std::size_t m = r.size();
  ic_y_.resize(m);
  for (std::size_t a = 0; a < m; ++a) {  // L y = r
    double v = r[a];
    for (std::uint32_t e = l_start_[a]; e < l_start_[a + 1]; ++e) v -= l_val_[e] * ic_y_[l_col_[e]];
    ic_y_[a] = v / l_diag_[a];
  }
  z.resize(m);
  for (std::size_t a = m; a-- > 0;) {  // L^T z = y, by columns of L^T (rows of L)
    z[a] = ic_y_[a] / l_diag_[a];
    for (std::uint32_t e = l_start_[a]; e < l_start_[a + 1]; ++e) ic_y_[l_col_[e]] -= l_val_[e] * z[a];
  }
}

}  // namespace mrf
