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
  // Control characters of the user's text (a NUL would cut the message
  // short where it is printed) are shown as \xNN.
  static std::string printable(const std::string& t) {
    static const char hex[] = "0123456789abcdef";
    std::string s;
    for (const char ch : t) {
      const auto u = static_cast<unsigned char>(ch);
      if (u >= 0x20 && u != 0x7f) {
        s += ch;
      } else {
        s += "\\x";
        s += hex[u >> 4];
        s += hex[u & 15];
      }
    }
    return s;
  }
  static std::string format(const std::string& key, const std::string& value,
                            const std::string& where, const std::string& why) {
    std::string s = where.empty() ? std::string() : printable(where) + ": ";
    s += "key '" + printable(key) + "'";
    if (!value.empty()) s += " = " + printable(value);
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

// Writing a run's output failed (a full disk, a directory that cannot be
// written): the run stops at once, naming the file and the system's reason;
// what was written completely before (finished points, the last checkpoint,
// which is replaced atomically) stays as it was.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A checkpoint that cannot be trusted (damaged, truncated, foreign, of
// another format version) or cannot be resumed from (its time series is
// gone): the run refuses it rather than continuing from damaged state.
class CheckpointError : public NumericalError {
 public:
  using NumericalError::NumericalError;
};

}  // namespace mrf
