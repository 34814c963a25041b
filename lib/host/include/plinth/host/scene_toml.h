// Scene files (TOML). The keys, their units and their alternatives are documented in
// docs/scene-format.md; unknown keys and tables are rejected.
#pragma once

#include <cstddef>
#include <string>

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

}  // namespace plinth::host
