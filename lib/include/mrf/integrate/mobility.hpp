// The coupled part of a particle mobility, for the implicit contact step: a
// symmetric positive semi-definite operator C (1/kg) through which a force
// on one particle moves others (the fluid they share,
// coupling/fluid_response.hpp). The diagonal part stays a per-particle array.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mrf/vec.hpp"

namespace mrf {

class MobilityCoupling {
 public:
  // y_i += scale sum_j C_ij f_j, for every i or only those listed in `rows`.
  virtual void add(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                   const std::vector<std::uint32_t>* rows = nullptr) = 0;
  // The same with the operator the contact solve's Newton iterations take
  // for their Jacobian: C, or a cheaper approximation of it (the residual
  // is always taken with add()).
  virtual void add_jacobian(const std::vector<Vec3>& f, double scale, std::vector<Vec3>& y,
                            const std::vector<std::uint32_t>* rows = nullptr) {
    add(f, scale, y, rows);
  }
  virtual double diagonal(std::size_t i) const = 0;                 // C_ii
  virtual double coupling(std::size_t i, std::size_t k) const = 0;  // C_ik

 protected:
  ~MobilityCoupling() = default;
};

}  // namespace mrf
