// Host-side errors: thrown by file readers and scene loaders, caught at the command line.
#pragma once

#include <stdexcept>
#include <string>

namespace plinth::host {

// An input the user supplied is unusable. what() names the file (and line or key where there
// is one) and says what is wrong, e.g. "rec.AT2:4: cannot find NPTS= in the header line".
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace plinth::host
