// Binary archives for checkpoints. The writer collects the fields in memory
// and writes the file whole on close(), framed by a header and a checksum;
// the reader reads the file whole and verifies the frame before it hands out
// the first field. A foreign, old, truncated or damaged file is therefore
// refused with its reason instead of being resumed into a wrong state.
//
// Layout (little or big endian as the machine that wrote it):
//   offset 0       8 bytes  magic word "MRFCKPT\0"
//   offset 8       uint32   0x01020304, the byte-order marker
//   offset 12      uint32   format version, k_archive_version
//   offset 16      uint64   payload length P (bytes)
//   offset 24      P bytes  payload: the fields in the order they were put
//   offset 24 + P  uint32   CRC-32 (io/checksum.hpp) of bytes [0, 24 + P)
// Fields are stored in the machine's representation: scalars and trivially
// copyable structs as their bytes, Vec3 as three doubles, vectors and strings
// as a uint64 count and the elements. A checkpoint is resumed on the kind of
// machine that wrote it; the marker turns another kind into a clear refusal.
//
// Every refusal is an mrf::CheckpointError (a NumericalError) naming the path and the reason:
// "not an mrf checkpoint" (magic word), "written on a machine of other byte
// order", "format version X, this build reads Y", "truncated checkpoint"
// (also a read past the end of the payload) or "corrupt checkpoint"
// (checksum mismatch, size or marker inconsistent with the header).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/vec.hpp"

namespace mrf {

// Raise whenever the payload of any checkpoint changes (a field added,
// removed, reordered or retyped in a save/load or serialize): the reader then
// refuses old files by their version instead of misreading them. Version 1
// was the headerless format before the frame existed.
inline constexpr std::uint32_t k_archive_version = 11;  // 3: the stress series carries the cluster structure; 4: adaptive Verlet skin;
                                                       // 5: the coupling pair cache; 6: the implicit step's carrier paths;
                                                       // 7: the quasi-static minimiser; 8: its branch point;
                                                       // 9: a run's time origin (branches); 10: its CPU seconds
                                                       // 11: a branch's work counters at its branch point
inline constexpr std::string_view k_archive_magic{"MRFCKPT\0", 8};
inline constexpr std::uint32_t k_archive_byte_order = 0x01020304u;
inline constexpr std::size_t k_archive_header_bytes = 24;  // magic, marker, version, payload length
inline constexpr std::size_t k_archive_checksum_bytes = 4;

class ArchiveWriter {
 public:
  // Nothing touches `path` before close(): an archive abandoned by an
  // exception leaves no partial file.
  explicit ArchiveWriter(std::string path);
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(&v, sizeof(T));
  }
  void put(const Vec3& v) {
    for (int k = 0; k < 3; ++k) put(v[k]);
  }
  template <class T>
  void put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copy_constructible_v<T> || std::is_same_v<T, Vec3>);
    put<std::uint64_t>(v.size());
    append(v.data(), sizeof(T) * v.size());
  }
  void put(const std::string& s) {
    put<std::uint64_t>(s.size());
    append(s.data(), s.size());
  }
  // One field list for both directions (see ArchiveReader::io): a type with a
  // static `serialize(Archive&, Self&)` member template is serialised by it,
  // anything else is put.
  template <class... T>
  void io(const T&... v) {
    (io_one(v), ...);
  }
  // Fills in the header, appends the checksum and writes the file atomically
  // (io/atomic_file.hpp: `path`.tmp, then a rename). Throws std::runtime_error
  // when the file cannot be written.
  void close();

 private:
  void append(const void* p, std::size_t n) { bytes_.append(static_cast<const char*>(p), n); }
  template <class T>
  void io_one(const T& v) {
    if constexpr (requires { T::serialize(*this, v); })
      T::serialize(*this, v);
    else
      put(v);
  }
  std::string path_;
  std::string bytes_;  // header (filled in by close) and payload
};

class ArchiveReader {
 public:
  // Reads `path` and verifies magic word, byte order, version, size and
  // checksum, in that order; throws CheckpointError on the first that fails
  // (std::runtime_error when the file cannot be read at all).
  explicit ArchiveReader(std::string path);
  template <class T>
  void get(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    take(&v, sizeof(T));
  }
  void get(Vec3& v) {
    for (int k = 0; k < 3; ++k) get(v[k]);
  }
  template <class T>
  void get(std::vector<T>& v) {
    static_assert(std::is_trivially_copy_constructible_v<T> || std::is_same_v<T, Vec3>);
    v.resize(count(sizeof(T)));
    take(v.data(), sizeof(T) * v.size());
  }
  void get(std::string& s) {
    s.resize(count(1));
    take(s.data(), s.size());
  }
  template <class... T>
  void io(T&... v) {
    (io_one(v), ...);
  }
  // Payload bytes not yet read.
  std::size_t remaining() const { return end_ - pos_; }
  // Throws CheckpointError unless the whole payload has been read: a reader
  // that takes fewer fields than the writer put is out of step with it.
  void expect_end() const;
  const std::string& path() const { return path_; }

 private:
  template <class T>
  void io_one(T& v) {
    if constexpr (requires { T::serialize(*this, v); })
      T::serialize(*this, v);
    else
      get(v);
  }
  // Reads an element count and checks that `element_bytes` times it are left,
  // so a damaged count fails as a truncation instead of a huge allocation.
  std::size_t count(std::size_t element_bytes);
  void take(void* dst, std::size_t n) {
    if (n > remaining()) past_end("a field of " + std::to_string(n) + " bytes");
    if (n) std::memcpy(dst, bytes_.data() + pos_, n);
    pos_ += n;
  }
  [[noreturn]] void past_end(const std::string& field) const;
  std::string path_;
  std::string bytes_;  // the whole file
  std::size_t pos_ = 0, end_ = 0;  // payload read position and end, offsets in bytes_
};

}  // namespace mrf
