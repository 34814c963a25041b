// SHA-256 (FIPS 180-4) and HMAC-SHA256 (RFC 2104): the box's digests of its files and the tags
// that authenticate a regional alert's source (regional_alert.h, RegionalAuthentication).
// Freestanding: no heap.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace plinth::monitor {

using Sha256Digest = std::array<std::uint8_t, 32>;

// A message's SHA-256, fed in pieces.
class Sha256 {
 public:
  Sha256();
  void update(const std::uint8_t* bytes, std::size_t size);
  [[nodiscard]] Sha256Digest finish();  // once; the object is then spent

 private:
  std::array<std::uint32_t, 8> state_;
  std::array<std::uint8_t, 64> block_{};
  std::size_t block_used_ = 0;
  std::uint64_t length_ = 0;  // bytes so far
};

// HMAC-SHA256 of `size` bytes with a 32-byte key (the block size's 64 bytes: keys of 32 are
// padded with zeros, RFC 2104). `parts` lets a tag cover several pieces (frames, a counter)
// without copying them together.
struct ByteSpan {
  const std::uint8_t* bytes;
  std::size_t size;
};
[[nodiscard]] Sha256Digest hmac_sha256(const std::array<std::uint8_t, 32>& key,
                                       const ByteSpan* parts, std::size_t part_count);

// Equal in time independent of where they differ (a tag compared byte by byte would say how
// many leading bytes a forger got right).
[[nodiscard]] bool same_bytes(const std::uint8_t* a, const std::uint8_t* b, std::size_t size);

}  // namespace plinth::monitor
