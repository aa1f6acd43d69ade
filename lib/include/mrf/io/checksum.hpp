// CRC-32 of a byte string, the checksum that ends a checkpoint (io/archive.hpp).
// CRC-32 rather than a hash such as FNV-1a because it is the one zlib, gzip
// and PNG use (the reflected polynomial 0xEDB88320, ISO-HDLC / IEEE 802.3):
// a checkpoint can be checked outside mrf, e.g. Python's zlib.crc32 over all
// bytes but the last four, and it detects every burst error up to 32 bits.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>

namespace mrf {

namespace detail {

// The byte-at-a-time table: entry b is the CRC register after shifting in b.
constexpr std::array<std::uint32_t, 256> crc32_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t r = b;
    for (int k = 0; k < 8; ++k) r = (r & 1u) ? (r >> 1) ^ 0xEDB88320u : r >> 1;
    t[b] = r;
  }
  return t;
}

inline constexpr std::array<std::uint32_t, 256> k_crc32_table = crc32_table();

}  // namespace detail

// CRC-32 of `bytes`, continuing from `crc`, the CRC of the bytes before them
// (zlib's convention): crc32(b, crc32(a)) == crc32(a + b), crc32("") == 0.
constexpr std::uint32_t crc32(std::string_view bytes, std::uint32_t crc = 0) {
  std::uint32_t r = ~crc;
  for (const char c : bytes) r = detail::k_crc32_table[(r ^ static_cast<unsigned char>(c)) & 0xFFu] ^ (r >> 8);
  return ~r;
}

}  // namespace mrf
