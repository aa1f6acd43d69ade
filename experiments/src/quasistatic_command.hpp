#pragma once
#include <string>
#include <vector>

#include "mrf/quasistatic/aqs.hpp"

struct QuasistaticCliOptions {
  bool quiet = false;
  bool resume = false;            // continue from OUT/checkpoint.bin
  std::string branch_from;        // or start from another run's checkpoint, at this run's tolerance
  std::string start_from;         // or from the last frame of an `mrf run` frames.xyz of the same scene
  double checkpoint_seconds = 60; // wall seconds between checkpoints (0: only at the end)
};

// `mrf quasistatic SCENE [--set k=v]... [--out DIR] [--increment D] [--tol T] [--no-affine] [--cutoff R]
//  [--minimiser M] [--resume] [--branch-from CHECKPOINT] [--start-from FRAMES] [--checkpoint-every S]` (see quasistatic_command.cpp).
int quasistatic_command(const std::string& scene, const std::vector<std::string>& sets, std::string out,
                        const mrf::QuasistaticOptions& opt, const QuasistaticCliOptions& cli);
