// Quantities as a user writes them: a plain number (SI) or a string
// "<number> <unit>", converted to SI and checked against an allowed interval.
// Used by the scene loader (io/toml_scene) for files and --set overrides; the
// accepted units are listed in docs/scene-format.md.
//
// A rejected value throws mrf::ValueError whose what() is the reason only;
// the caller adds key, value and location (mrf::InputError).
#pragma once
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

namespace mrf {

// Physical dimension of a scene key; `none` is a dimensionless number.
enum class Dim { none, length, time, pressure, viscosity, density, magnetization, rate, velocity };

std::string_view noun(Dim d);      // "a length", ...
std::string unit_list(Dim d);      // "m, mm, um, nm"; empty for Dim::none
std::string expects(Dim d);        // what a value of this dimension may look like

// Unit spelling as looked up: micro sign and Greek mu become 'u', runs of
// blanks one space ("Pa  s" -> "Pa s", "µm" -> "um").
std::string normalize_unit(std::string_view unit);

std::string_view trim(std::string_view s);  // without leading/trailing blanks
std::string format_number(double x);        // shortest text that reads back exactly
std::string format_short(double x, int digits = 6);  // %.<digits>g: derived numbers in messages

class ValueError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "<number> <unit>" (or "<number>" for Dim::none) -> SI value.
double parse_quantity(std::string_view text, Dim dim);

// Allowed interval of a number (open ends are strict).
struct Range {
  double lo, hi;
  bool lo_open, hi_open;
};
inline constexpr double k_inf = std::numeric_limits<double>::infinity();
inline constexpr Range k_any{-k_inf, k_inf, false, false};
inline constexpr Range k_pos{0, k_inf, true, false};
inline constexpr Range k_nonneg{0, k_inf, false, false};

bool inside(double x, const Range& r);
std::string describe(const Range& r);  // "must be > 0", "must be in [0, 1)"

// One value from a file or an override, before conversion.
struct WrittenValue {
  // integer, float, bool, string; monostate for anything else (array, table).
  std::variant<std::monostate, std::int64_t, double, bool, std::string> v;
  std::string text;   // as shown in messages
  std::string where;  // "FILE:LINE" or "--set key=value"
};

// A finite number of dimension `dim` inside `range`: an integer or float is
// taken as SI, a string is parsed by parse_quantity.
double read_number(const WrittenValue& val, Dim dim, const Range& range = k_any);

// An integer >= 0 that fits `Int`.
template <class Int>
Int read_count(const WrittenValue& val) {
  const auto* i = std::get_if<std::int64_t>(&val.v);
  if (!i) throw ValueError("expected an integer");
  if (*i < 0) throw ValueError("must be an integer >= 0");
  if (static_cast<std::uint64_t>(*i) > static_cast<std::uint64_t>(std::numeric_limits<Int>::max()))
    throw ValueError("integer too large");
  return static_cast<Int>(*i);
}

}  // namespace mrf
