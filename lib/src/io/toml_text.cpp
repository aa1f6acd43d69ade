#include "mrf/io/toml_text.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

#include "mrf/io/quantity.hpp"

namespace mrf {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string toml_header_name(std::string_view line) {
  const std::string_view inner = line.substr(0, line.find(']'));
  const auto b = inner.find_first_not_of('[');
  return b == std::string_view::npos ? "" : std::string(trim(inner.substr(b)));
}

std::pair<std::string, std::string> toml_key_on_line(std::string_view text, std::uint32_t line) {
  std::string section, current;
  std::istringstream in{std::string(text)};
  std::string l;
  for (std::uint32_t n = 1; n <= line && std::getline(in, l); ++n) {
    const std::string_view t = trim(l);
    if (n == line) current = t;
    else if (t.starts_with('[')) section = toml_header_name(t);
  }
  const auto eq = current.find('=');
  if (eq == std::string::npos) return {current.empty() ? "(end of file)" : current, ""};
  const std::string name(trim(std::string_view(current).substr(0, eq)));
  return {section.empty() ? name : section + "." + name,
          std::string(trim(std::string_view(current).substr(eq + 1)))};
}

}  // namespace mrf
