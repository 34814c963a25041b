// What every fuzz target shares: the invariant check that turns a broken promise into a crash
// libFuzzer reports (and keeps the input of), and the text view of the input.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

namespace plinth::fuzz {

// Aborts with a message when `condition` is false: an invariant of the code under test broke.
inline void check(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace plinth::fuzz
