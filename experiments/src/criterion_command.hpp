#pragma once
#include <string>

// `mrf criterion PATH [--thresholds FILE]` (see criterion_command.cpp).
int criterion_command(const std::string& path, const std::string& thresholds_path);
