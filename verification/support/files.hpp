// File helpers for tests that write and read back real files.
#pragma once
#include <filesystem>
#include <string>

namespace mrf::test {

// A fresh directory under the system temp dir, unique to the process and the
// name, removed on destruction, so parallel ctest runs do not share files.
class TempDir {
 public:
  explicit TempDir(const std::string& name);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The whole file as bytes ("" if it cannot be read).
std::string read_bytes(const std::filesystem::path& p);
// Replaces the file with `bytes`.
void write_bytes(const std::filesystem::path& p, const std::string& bytes);

}  // namespace mrf::test
