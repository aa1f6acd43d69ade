// A minimal binary archive for checkpoints: scalars and vectors of trivially
// copyable values, written in the machine's representation (a checkpoint is
// resumed on the machine kind that wrote it; Vec3 is stored as its three
// doubles), framed by a magic word, a
// format version and a fingerprint of the scene so that a checkpoint is never
// resumed into a different run.
#pragma once
#include <cstdint>
#include <fstream>
#include <string>
#include <type_traits>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/vec.hpp"

namespace mrf {

class ArchiveWriter {
 public:
  explicit ArchiveWriter(const std::string& path) : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
    if (!out_) throw std::runtime_error("cannot write checkpoint " + path);
  }
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put(const Vec3& v) {
    for (int k = 0; k < 3; ++k) put(v[k]);
  }
  template <class T>
  void put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copy_constructible_v<T> || std::is_same_v<T, Vec3>);
    put<std::uint64_t>(v.size());
    if (!v.empty()) out_.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(sizeof(T) * v.size()));
  }
  void put(const std::string& s) {
    put<std::uint64_t>(s.size());
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  void close() {
    out_.flush();
    if (!out_) throw std::runtime_error("checkpoint write failed: " + path_);
    out_.close();
  }

 private:
  std::string path_;
  std::ofstream out_;
};

class ArchiveReader {
 public:
  explicit ArchiveReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw std::runtime_error("cannot read checkpoint " + path);
  }
  template <class T>
  void get(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    in_.read(reinterpret_cast<char*>(&v), sizeof(T));
    check();
  }
  void get(Vec3& v) {
    for (int k = 0; k < 3; ++k) get(v[k]);
  }
  template <class T>
  void get(std::vector<T>& v) {
    static_assert(std::is_trivially_copy_constructible_v<T> || std::is_same_v<T, Vec3>);
    std::uint64_t n = 0;
    get(n);
    if (n > (std::uint64_t{1} << 32)) throw NumericalError("corrupt checkpoint " + path_ + " (vector size)");
    v.resize(n);
    if (n) in_.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(sizeof(T) * n));
    check();
  }
  void get(std::string& s) {
    std::uint64_t n = 0;
    get(n);
    if (n > (std::uint64_t{1} << 24)) throw NumericalError("corrupt checkpoint " + path_ + " (string size)");
    s.resize(n);
    in_.read(s.data(), static_cast<std::streamsize>(n));
    check();
  }

 private:
  void check() {
    if (!in_) throw NumericalError("truncated checkpoint " + path_);
  }
  std::string path_;
  std::ifstream in_;
};

}  // namespace mrf
