// What a box runs: the build's version (plinth/version/version.h) and the SHA-256 of each file
// it was started with (the scene, the second axis's scene, the box's configuration). The first
// status line and each capture's JSON carry them (docs/monitor.md), so a record says which
// build and which configuration made it; the Modbus server and the MQTT publisher take the same
// identity once at start (docs/integration.md). SHA-256 rather than a shorter non-cryptographic
// hash: anyone on the box checks it with `sha256sum /etc/plinth/statue.toml`, and no edit of a
// file keeps its digest.
// Host code: allocates and throws.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace plinth::firmware {

using Sha256Digest = std::array<std::uint8_t, 32>;

// SHA-256 (FIPS 180-4) of `bytes`.
[[nodiscard]] Sha256Digest sha256(std::string_view bytes);
// Of a file's bytes; throws host::InputError naming the file when it cannot be read.
[[nodiscard]] Sha256Digest file_sha256(const std::string& path);
// 64 lowercase hex digits, as sha256sum prints them.
[[nodiscard]] std::string hex(const Sha256Digest& digest);
// The digest's first 8 bytes as a number, big-endian (four 16-bit registers).
[[nodiscard]] std::uint64_t leading_64_bits(const Sha256Digest& digest);

struct RunIdentity {
  std::string version;                   // kVersionText: "0.1.0 (v0.1.0-12-gabcdef0)"
  std::optional<Sha256Digest> scene;     // of each file; none when it was not given
  std::optional<Sha256Digest> scene_y;
  std::optional<Sha256Digest> config;
};

// A digest with the name of its JSON member and of its file.
struct NamedDigest {
  const char* member;  // "scene_sha256", "scene_y_sha256", "config_sha256"
  const char* file;    // "Scene", "Scene y", "Box file"
  const std::optional<Sha256Digest>* digest;
};
// The identity's digests in that order.
[[nodiscard]] std::array<NamedDigest, 3> named_digests(const RunIdentity& identity);

// The build's version and the digests of the files given ("" paths are left out).
[[nodiscard]] RunIdentity run_identity(const std::string& scene_path,
                                       const std::string& scene_y_path,
                                       const std::string& config_path);

// The identity as JSON members, written already: "version": "...", "scene_sha256": "...",
// and "scene_y_sha256", "config_sha256" when those files were given.
[[nodiscard]] std::string identity_members(const RunIdentity& identity);

// `object` (a JSON object, "{...}") with `members` added at its end.
[[nodiscard]] std::string with_members(const std::string& object, const std::string& members);

}  // namespace plinth::firmware
