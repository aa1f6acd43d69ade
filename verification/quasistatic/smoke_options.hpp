// The quasi-static options of the small-scene tests (test_aqs.cpp,
// test_aqs_resume.cpp): five increments of 1e-3 at tol 1e-6 F0.
#pragma once
#include "mrf/quasistatic/aqs.hpp"

namespace mrf::test {

inline QuasistaticOptions smoke_options() {
  QuasistaticOptions o;
  o.strain_increment = 1e-3;
  o.strain = 5e-3;
  o.warmup_strain = 0.0;
  o.force_tol = 1e-6;
  return o;
}

}  // namespace mrf::test
