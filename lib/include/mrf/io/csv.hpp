// One line of the project's CSV files (sweep.csv, timeseries.csv): fields
// split at commas, no quoting (no field holds a comma); a trailing comma
// ends in an empty field.
#pragma once
#include <sstream>
#include <string>
#include <vector>

namespace mrf {

inline std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace mrf
