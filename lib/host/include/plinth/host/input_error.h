// Host-side errors: thrown by file readers and scene loaders, caught at the command line.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>

#include "plinth/core/error.h"
#include "plinth/core/scene.h"

namespace plinth::host {

// An input the user supplied is unusable. what() names the file (and line or key where there
// is one) and says what is wrong, e.g. "rec.AT2:4: cannot find NPTS= in the header line".
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// A text shown in a message with its invisible characters escaped (a tab as \t, a carriage
// return as \r, a line feed as \n, a UTF-8 byte order mark as \ufeff, any other control byte
// as \xNN, a backslash as \\) and quoted: what the user typed or the file held, as it is.
[[nodiscard]] std::string shown(std::string_view text);

// A whole message made printable the same way, its own line breaks kept: every tool prints its
// errors (run_tool, parse_command_line) and warnings through it, so whatever text of the user's
// a message quotes, a stray tab, carriage return or byte order mark shows as what it is.
[[nodiscard]] std::string printable(std::string_view message);

// Throws the InputError a command-line tool shows for a failed Simulator::create of `scene` at
// the step `step` (s, the tools' --dt). A step too large for the scene's base names --dt with
// its value and the largest stable step, and the base's keys that set that limit (its period,
// mass and damping: a stiff or light base); when no step a tool can take would do (the limit
// below kSmallestUsableStep), the base alone is blamed.
inline constexpr double kSmallestUsableStep = 1e-9;  // s
void throw_if_simulator_error(const Error& e, const Scene& scene, double step);

}  // namespace plinth::host
