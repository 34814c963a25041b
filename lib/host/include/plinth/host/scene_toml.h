// Scene files (TOML). The keys, their units and their alternatives are documented in
// docs/scene-format.md; unknown keys and tables are rejected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <optional>

#include "plinth/core/fragility.h"
#include "plinth/core/scene.h"

namespace plinth::host {

// Parses a scene file into SI SceneParams and validates it with make_scene. Throws InputError
// with the file name, and the key (and line, where toml++ knows it) at fault, for: missing
// file, TOML syntax errors, unknown tables or keys, wrong types, both alternatives of a pair
// given (e.g. slenderness and com_height), a required key missing, and every error
// make_scene reports (mapped back to the key the file used).
[[nodiscard]] Scene load_scene_file(const std::string& path);

// A scene file is a few hundred bytes; longer than this it is refused, unread (text_file.h).
inline constexpr std::size_t kMaxSceneFileBytes = std::size_t{1} << 20;  // 1 MiB

// The same from TOML text; `origin` is used in messages in place of a file name.
[[nodiscard]] Scene load_scene_text(const std::string& text, const std::string& origin);

// One key whose true value is uncertain: `[uncertainty.<table>] <key> = [low, high]`, in the
// key's own unit; nominal is the scene's value (given, or the key's constant default).
struct UncertainKey {
  std::string table;  // "block"
  std::string key;    // "slenderness"
  double nominal = 0.0;
  double low = 0.0;
  double high = 0.0;
  std::uint32_t line = 0;
};

// A scene file with its declared uncertainty (docs/scene-format.md, [uncertainty]).
struct UncertainScene {
  Scene nominal;
  std::vector<UncertainKey> uncertain;  // in file order
  // The ensemble: the two-level design over `uncertain` (plinth/core/ensemble_design.h), each
  // point's keys at low (z = -1), the scene's value (0) or high (+1); members[0] is nominal.
  // Each member is validated as a scene of its own.
  std::vector<Scene> members;
  // The statue's collapse fragility, when the file gives it ([fragility]: median_g, beta; what
  // plinth-eval fragility fits for the scene): the box's P-wave stage needs it (docs/pwave.md).
  std::optional<LognormalFragility> fragility;

  // A statue inside the ranges: key i at low + u[i] (high - low), u[i] in [0, 1] (missing
  // entries: the middle). Throws InputError naming the values when they make no valid scene.
  [[nodiscard]] Scene statue(std::span<const double> u) const;

 private:
  friend UncertainScene load_uncertain_scene_text(const std::string&, const std::string&);
  [[nodiscard]] Scene scene_at(const std::vector<double>& values) const;
  std::string text_;  // the file, read again for each statue
  std::string origin_;
};

// Reads a scene file and its [uncertainty] table. Throws InputError naming the file, line and
// key for everything load_scene_file refuses, and for: an uncertainty sub-table the scene does
// not have, a key its table does not know or the scene does not give (unless it has a constant
// default), a range that is not two finite numbers [low, high] holding the scene's value, more
// than kMaxUncertainParameters keys, a member of the ensemble that is not a valid scene, and a
// [fragility] table without both keys, with others, a median_g not above 0 or a beta below 0.
[[nodiscard]] UncertainScene load_uncertain_scene_file(const std::string& path);
[[nodiscard]] UncertainScene load_uncertain_scene_text(const std::string& text,
                                                       const std::string& origin);

}  // namespace plinth::host
