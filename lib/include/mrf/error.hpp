// Error types: bad input names key, value and source line; numerical failures
// name the quantity, the particle and the step where they appeared.
#pragma once
#include <stdexcept>
#include <string>

namespace mrf {

// Bad user input (scene file, --set override, command line).
// `where` is "FILE:LINE" or "--set" and may be empty.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& key, const std::string& value, const std::string& where,
             const std::string& why)
      : std::runtime_error(format(key, value, where, why)), key_(key), value_(value), why_(why) {}
  const std::string& key() const { return key_; }
  // The same error placed at `where` (a caller that knows the file line).
  InputError at(const std::string& where) const { return InputError(key_, value_, where, why_); }

 private:
  static std::string format(const std::string& key, const std::string& value,
                            const std::string& where, const std::string& why) {
    std::string s = where.empty() ? std::string() : where + ": ";
    s += "key '" + key + "'";
    if (!value.empty()) s += " = " + value;
    s += ": " + why;
    return s;
  }
  std::string key_, value_, why_;
};

// A run produced a non-finite number or left a stability bound.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mrf
