#include "mrf/io/archive.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "mrf/io/atomic_file.hpp"
#include "mrf/io/checksum.hpp"

namespace mrf {

namespace {

// Offsets of the header fields (layout in io/archive.hpp).
constexpr std::size_t k_order_at = 8, k_version_at = 12, k_payload_at = 16;

std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%08llx", static_cast<unsigned long long>(v));
  return buf;
}

template <class T>
T read_at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

template <class T>
void write_at(std::string& bytes, std::size_t offset, T v) {
  std::memcpy(bytes.data() + offset, &v, sizeof(T));
}

std::uint32_t byte_swap(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xFF00u) | ((v << 8) & 0xFF0000u) | (v << 24);
}

}  // namespace

ArchiveWriter::ArchiveWriter(std::string path) : path_(std::move(path)), bytes_(k_archive_header_bytes, '\0') {}

void ArchiveWriter::close() {
  const std::uint64_t payload = bytes_.size() - k_archive_header_bytes;
  bytes_.replace(0, k_archive_magic.size(), k_archive_magic);
  write_at(bytes_, k_order_at, k_archive_byte_order);
  write_at(bytes_, k_version_at, k_archive_version);
  write_at(bytes_, k_payload_at, payload);
  put(crc32(bytes_));
  write_file_atomic(path_, bytes_);
}

ArchiveReader::ArchiveReader(std::string path) : path_(std::move(path)) {
  std::ifstream in(path_, std::ios::binary);
  std::error_code ec;
  const auto size = std::filesystem::file_size(path_, ec);
  if (!in || ec) throw CheckpointError("cannot read checkpoint " + path_);
  bytes_.resize(size);
  in.read(bytes_.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) throw CheckpointError("cannot read checkpoint " + path_);

  const auto refuse = [&](const std::string& why) { throw CheckpointError(path_ + ": " + why); };
  const std::size_t n = bytes_.size();
  // A file cut inside the magic word still starts with a prefix of it.
  if (std::string_view(bytes_).substr(0, k_archive_magic.size()) != k_archive_magic.substr(0, n))
    refuse("not an mrf checkpoint (it does not start with the magic word MRFCKPT; checkpoints of mrf before "
           "format version 2 have none)");
  if (n < k_archive_header_bytes)
    refuse("truncated checkpoint (" + std::to_string(n) + " bytes, shorter than the " +
           std::to_string(k_archive_header_bytes) + "-byte header)");
  const auto order = read_at<std::uint32_t>(bytes_, k_order_at);
  if (order == byte_swap(k_archive_byte_order))
    refuse("written on a machine of other byte order; resume it on a machine of the kind that wrote it");
  if (order != k_archive_byte_order)
    refuse("corrupt checkpoint: byte-order marker " + hex(order) + " is neither " + hex(k_archive_byte_order) +
           " nor its byte swap");
  // The version comes before size and checksum: another version may frame its payload differently.
  const auto version = read_at<std::uint32_t>(bytes_, k_version_at);
  if (version != k_archive_version)
    refuse("format version " + std::to_string(version) + ", this build reads " + std::to_string(k_archive_version) +
           ": rerun from the start or use the mrf that wrote it");
  const auto payload = read_at<std::uint64_t>(bytes_, k_payload_at);
  const std::size_t frame = k_archive_header_bytes + k_archive_checksum_bytes;
  if (n < frame || payload > n - frame)
    refuse("truncated checkpoint (" + std::to_string(n) + " bytes of the " + std::to_string(payload + frame) +
           " its header announces)");
  if (payload != n - frame)
    refuse("corrupt checkpoint: size mismatch (" + std::to_string(n) + " bytes, the header announces " +
           std::to_string(payload + frame) + ")");
  const auto stored = read_at<std::uint32_t>(bytes_, n - k_archive_checksum_bytes);
  const std::uint32_t computed = crc32(std::string_view(bytes_).substr(0, n - k_archive_checksum_bytes));
  if (stored != computed)
    refuse("corrupt checkpoint: checksum mismatch (the file says CRC-32 " + hex(stored) + ", its bytes give " +
           hex(computed) + ")");
  pos_ = k_archive_header_bytes;
  end_ = n - k_archive_checksum_bytes;
}

std::size_t ArchiveReader::count(std::size_t element_bytes) {
  std::uint64_t n = 0;
  get(n);
  if (n > remaining() / element_bytes)
    past_end("a count of " + std::to_string(n) + " elements of " + std::to_string(element_bytes) + " bytes");
  return static_cast<std::size_t>(n);
}

void ArchiveReader::past_end(const std::string& field) const {
  throw CheckpointError(path_ + ": truncated checkpoint: reading " + field + " at payload byte " +
                       std::to_string(pos_ - k_archive_header_bytes) + " of " +
                       std::to_string(end_ - k_archive_header_bytes) +
                       " (this build reads more fields than the writer put)");
}

void ArchiveReader::expect_end() const {
  if (remaining() != 0)
    throw CheckpointError(path_ + ": corrupt checkpoint: " + std::to_string(remaining()) +
                         " payload bytes left unread (this build reads fewer fields than the writer put)");
}

}  // namespace mrf
