#include "run_identity.h"

#include <cstdio>

#include "plinth/host/input_error.h"
#include "plinth/host/text_file.h"
#include "plinth/version/version.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

// FIPS 180-4, 4.2.2: the first 32 bits of the fractional parts of the cube roots of the first
// 64 primes.
constexpr std::uint32_t kRoundConstants[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
    0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
    0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
    0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
    0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
    0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
    0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
    0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
    0xc67178f2};

constexpr std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

// FIPS 180-4, 6.2.2: one 64-byte block into the hash value `h`.
void compress(std::array<std::uint32_t, 8>& h, const std::uint8_t* block) {
  std::uint32_t w[64];
  for (int t = 0; t < 16; ++t) {
    w[t] = static_cast<std::uint32_t>(block[4 * t]) << 24 |
           static_cast<std::uint32_t>(block[4 * t + 1]) << 16 |
           static_cast<std::uint32_t>(block[4 * t + 2]) << 8 | block[4 * t + 3];
  }
  for (int t = 16; t < 64; ++t) {
    const std::uint32_t s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
    const std::uint32_t s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
    w[t] = w[t - 16] + s0 + w[t - 7] + s1;
  }
  std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], k = h[7];
  for (int t = 0; t < 64; ++t) {
    const std::uint32_t t1 = k + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) +
                             kRoundConstants[t] + w[t];
    const std::uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    k = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  h[0] += a;
  h[1] += b;
  h[2] += c;
  h[3] += d;
  h[4] += e;
  h[5] += f;
  h[6] += g;
  h[7] += k;
}

// The largest scene or box file read (the box's own readers refuse larger ones).
constexpr std::size_t kMaxHashedBytes = std::size_t{16} << 20;

}  // namespace

Sha256Digest sha256(std::string_view bytes) {
  // FIPS 180-4, 5.3.3: the initial hash value.
  std::array<std::uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  std::size_t whole = bytes.size() / 64 * 64;
  for (std::size_t i = 0; i < whole; i += 64) compress(h, data + i);
  // 5.1.1: padding, a 1 bit, zeros, the message's length in bits (64 bits, big-endian).
  std::uint8_t tail[128] = {};
  const std::size_t rest = bytes.size() - whole;
  for (std::size_t i = 0; i < rest; ++i) tail[i] = data[whole + i];
  tail[rest] = 0x80;
  const std::size_t tail_size = rest + 9 <= 64 ? 64 : 128;
  const std::uint64_t bits = static_cast<std::uint64_t>(bytes.size()) * 8;
  for (int i = 0; i < 8; ++i) {
    tail[tail_size - 1 - static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (8 * i));
  }
  for (std::size_t i = 0; i < tail_size; i += 64) compress(h, tail + i);
  Sha256Digest out{};
  for (std::size_t i = 0; i < 8; ++i) {
    for (std::size_t j = 0; j < 4; ++j) {
      out[4 * i + j] = static_cast<std::uint8_t>(h[i] >> (24 - 8 * j));
    }
  }
  return out;
}

Sha256Digest file_sha256(const std::string& path) {
  return sha256(host::read_text_file(path, kMaxHashedBytes, "file to identify"));
}

std::string hex(const Sha256Digest& digest) {
  std::string out;
  char two[3];
  for (const std::uint8_t byte : digest) {
    std::snprintf(two, sizeof two, "%02x", byte);
    out += two;
  }
  return out;
}

std::uint64_t leading_64_bits(const Sha256Digest& digest) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v = v << 8 | digest[i];
  return v;
}

RunIdentity run_identity(const std::string& scene_path, const std::string& scene_y_path,
                         const std::string& config_path) {
  RunIdentity id;
  id.version = version::kVersionText;
  const auto digest = [](const std::string& path) {
    return path.empty() ? std::nullopt : std::optional<Sha256Digest>(file_sha256(path));
  };
  id.scene = digest(scene_path);
  id.scene_y = digest(scene_y_path);
  id.config = digest(config_path);
  return id;
}

std::array<NamedDigest, 3> named_digests(const RunIdentity& identity) {
  return {{{"scene_sha256", "Scene", &identity.scene},
           {"scene_y_sha256", "Scene y", &identity.scene_y},
           {"config_sha256", "Box file", &identity.config}}};
}

std::string identity_members(const RunIdentity& identity) {
  JsonObject o;
  o.text("version", identity.version);
  for (const NamedDigest& d : named_digests(identity)) {
    if (d.digest->has_value()) o.text(d.member, hex(**d.digest));
  }
  const std::string object = o.close();
  return object.substr(1, object.size() - 2);  // without the braces
}

std::string with_members(const std::string& object, const std::string& members) {
  if (members.empty() || object.size() < 2 || object.back() != '}') return object;
  const bool empty = object.size() == 2;
  return object.substr(0, object.size() - 1) + (empty ? "" : ", ") + members + "}";
}

}  // namespace plinth::firmware
