// What was built: every program's --version, the box's first status line, its Modbus registers,
// MQTT state and captures report these (lib/version/CMakeLists.txt makes them at build time).
#pragma once

namespace plinth::version {

// The project's version, "MAJOR.MINOR.PATCH" (project() in the top CMakeLists.txt).
extern const char kProjectVersion[];
// `git describe --always --dirty --tags --long` of the source tree at build time, or the
// PLINTH_GIT_DESCRIPTION cache variable, or "unknown"; only [A-Za-z0-9._+~-].
extern const char kGitDescription[];
// "VERSION (DESCRIPTION)": what --version prints after the program's name.
extern const char kVersionText[];

}  // namespace plinth::version
