#pragma once
#include <string>
#include <vector>

#include "mrf/quasistatic/aqs.hpp"

// `mrf quasistatic SCENE [--set k=v]... [--out DIR] [--increment D] [--tol T] [--no-affine] [--cutoff R]`
// (see quasistatic_command.cpp).
int quasistatic_command(const std::string& scene, const std::vector<std::string>& sets, std::string out,
                        const mrf::QuasistaticOptions& opt, bool quiet);
