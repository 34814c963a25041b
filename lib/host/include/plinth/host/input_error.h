// Host-side errors: thrown by file readers and scene loaders, caught at the command line.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

#include "plinth/core/error.h"

namespace plinth::host {

// An input the user supplied is unusable. what() names the file (and line or key where there
// is one) and says what is wrong, e.g. "rec.AT2:4: cannot find NPTS= in the header line".
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// Throws the InputError a command-line tool shows for a failed Simulator::create: the solver's
// step is the tools' --dt, and a largest stable step is quoted.
inline void throw_if_simulator_error(const Error& e) {
  if (e.ok()) return;
  std::string message = std::string(std::string(e.field) == "solver.step" ? "--dt" : e.field) +
                        ": " + e.reason;
  if (e.limit > 0.0) {
    char limit[64];
    std::snprintf(limit, sizeof limit, "; the largest stable step is %.3g s", e.limit);
    message += limit;
  }
  throw InputError(message);
}

}  // namespace plinth::host
