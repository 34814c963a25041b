#include "run_identity.h"

#include <cstdio>

#include "plinth/host/input_error.h"
#include "plinth/host/text_file.h"
#include "plinth/monitor/hmac_sha256.h"
#include "plinth/version/version.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

// The largest scene or box file read (the box's own readers refuse larger ones).
constexpr std::size_t kMaxHashedBytes = std::size_t{16} << 20;

}  // namespace

Sha256Digest sha256(std::string_view bytes) {
  monitor::Sha256 hash;
  hash.update(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return hash.finish();
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
