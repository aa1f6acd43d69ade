#include <cstdio>
#include "mrf/io/quantity.hpp"

#include <charconv>
#include <cmath>

namespace mrf {
namespace {

struct Unit {
  Dim dim;
  std::string_view name;  // after normalize_unit
  double factor;          // to SI
};

constexpr Unit k_units[] = {
    {Dim::length, "m", 1}, {Dim::length, "mm", 1e-3}, {Dim::length, "um", 1e-6},
    {Dim::length, "nm", 1e-9},
    {Dim::time, "s", 1}, {Dim::time, "ms", 1e-3}, {Dim::time, "us", 1e-6}, {Dim::time, "ns", 1e-9},
    {Dim::pressure, "Pa", 1}, {Dim::pressure, "kPa", 1e3}, {Dim::pressure, "MPa", 1e6},
    {Dim::pressure, "GPa", 1e9},
    {Dim::viscosity, "Pa s", 1}, {Dim::viscosity, "Pa*s", 1}, {Dim::viscosity, "mPa s", 1e-3},
    {Dim::viscosity, "mPa*s", 1e-3},
    {Dim::density, "kg/m^3", 1}, {Dim::density, "kg/m3", 1}, {Dim::density, "g/cm^3", 1e3},
    {Dim::density, "g/cm3", 1e3},
    {Dim::magnetization, "A/m", 1}, {Dim::magnetization, "kA/m", 1e3},
    {Dim::magnetization, "MA/m", 1e6},
    {Dim::rate, "1/s", 1}, {Dim::rate, "s^-1", 1},
    {Dim::velocity, "m/s", 1},
};

// Indexed by Dim.
constexpr std::string_view k_nouns[] = {"a dimensionless number", "a length", "a time",
                                        "a pressure", "a viscosity", "a density",
                                        "a magnetization", "a rate", "a velocity"};

}  // namespace

std::string_view noun(Dim d) { return k_nouns[static_cast<std::size_t>(d)]; }

std::string unit_list(Dim d) {
  std::string s;
  for (const Unit& u : k_units)
    if (u.dim == d) s += (s.empty() ? "" : ", ") + std::string(u.name);
  return s;
}

std::string expects(Dim d) {
  if (d == Dim::none) return "expected a plain number";
  const std::string units = unit_list(d);
  return "expected a number in " + units.substr(0, units.find(',')) +
         " or a string \"<number> <unit>\" (units " + units + ")";
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

std::string normalize_unit(std::string_view u) {
  std::string s;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const std::string_view rest = u.substr(i);
    if (rest.starts_with("\u00b5") || rest.starts_with("\u03bc")) {
      s += 'u';
      ++i;  // both are two bytes in UTF-8
    } else if (u[i] == ' ' || u[i] == '\t') {
      if (s.empty() || s.back() != ' ') s += ' ';
    } else {
      s += u[i];
    }
  }
  return s;
}

std::string format_number(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

std::string format_short(double x, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

double parse_quantity(std::string_view text, Dim dim) {
  std::string_view t = trim(text);
  if (t.starts_with('+')) t.remove_prefix(1);
  double x = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), x);
  if (r.ec == std::errc::result_out_of_range) throw ValueError("number out of range");
  if (r.ec != std::errc()) throw ValueError(expects(dim));
  if (!std::isfinite(x)) throw ValueError("not a finite number");
  const std::string written(trim(std::string_view(r.ptr, t.data() + t.size() - r.ptr)));
  const std::string unit = normalize_unit(written);
  if (dim == Dim::none) {
    if (!unit.empty())
      throw ValueError("a dimensionless number takes no unit (got '" + written + "')");
    return x;
  }
  const std::string expected = std::string(noun(dim)) + " (expected " + unit_list(dim) + ")";
  if (unit.empty()) throw ValueError("missing unit for " + expected);
  for (const Unit& u : k_units) {
    if (u.name != unit) continue;
    if (u.dim != dim) throw ValueError("wrong unit '" + written + "' for " + expected);
    return x * u.factor;
  }
  throw ValueError("unknown unit '" + written + "' for " + expected);
}

bool inside(double x, const Range& r) {
  return (r.lo_open ? x > r.lo : x >= r.lo) && (r.hi_open ? x < r.hi : x <= r.hi);
}

std::string describe(const Range& r) {
  if (r.hi == k_inf) return (r.lo_open ? "must be > " : "must be >= ") + format_number(r.lo);
  return std::string("must be in ") + (r.lo_open ? "(" : "[") + format_number(r.lo) + ", " +
         format_number(r.hi) + (r.hi_open ? ")" : "]");
}

double read_number(const WrittenValue& val, Dim dim, const Range& range) {
  double x = 0;
  if (const auto* i = std::get_if<std::int64_t>(&val.v)) x = static_cast<double>(*i);
  else if (const auto* d = std::get_if<double>(&val.v)) x = *d;
  else if (const auto* s = std::get_if<std::string>(&val.v)) x = parse_quantity(*s, dim);
  else throw ValueError(expects(dim));
  if (!std::isfinite(x)) throw ValueError("not a finite number");
  if (!inside(x, range)) throw ValueError(describe(range));
  return x;
}

}  // namespace mrf
