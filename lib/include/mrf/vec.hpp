// Basic vector type and physical constants. SI units everywhere.
#pragma once
#include <Eigen/Core>
#include <numbers>

namespace mrf {

using Vec3 = Eigen::Vector3d;

inline constexpr double k_pi = std::numbers::pi;
// Vacuum permeability mu0 (H/m); the pre-2019 exact value, as in REFERENCE.md.
inline constexpr double k_mu0 = 4.0e-7 * k_pi;

// Volume of a sphere of radius r (m^3).
inline constexpr double sphere_volume(double r) { return 4.0 / 3.0 * k_pi * r * r * r; }

}  // namespace mrf
