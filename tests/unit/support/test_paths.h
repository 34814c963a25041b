#pragma once
// What every suite may use without a plinth library: the source tree and time in ns.
#include <cmath>
#include <cstdint>
#include <string>

namespace plinth::testing {

inline const std::string kSource = PLINTH_SOURCE_DIR;  // the source tree: records, scenes, DBC

inline std::int64_t ns(double seconds) { return std::llround(seconds * 1e9); }

}  // namespace plinth::testing
