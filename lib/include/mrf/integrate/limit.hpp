// A time-step limit: {name, dt, basis}. Every scheme's automatic step is
// built from a list of them (integrate/stability.hpp for the particles,
// fluid/wcsph.hpp for the SPH carrier); the start-up table prints them.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

namespace mrf {

struct StabilityLimit {
  std::string name;
  double dt;          // s; infinity when the scheme is not bound by it
  std::string basis;  // how it was computed, for the start-up printout
};

// The binding (smallest) limit of a non-empty list, and its dt.
inline const StabilityLimit& binding(const std::vector<StabilityLimit>& limits) {
  return *std::min_element(limits.begin(), limits.end(), [](const auto& a, const auto& b) { return a.dt < b.dt; });
}
inline double smallest(const std::vector<StabilityLimit>& limits) { return binding(limits).dt; }

}  // namespace mrf
