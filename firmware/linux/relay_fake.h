// A RelayBackend that records, for tests of the relay logic (relay_outputs.h): each line's
// level and every write in order; writes can be made to fail.
#pragma once

#include <cerrno>
#include <cstddef>
#include <vector>

#include "relay_outputs.h"

namespace plinth::firmware {

class FakeRelayBackend final : public RelayBackend {
 public:
  struct Write {
    std::size_t index;
    bool energised;
  };
  // `line_count` wired lines, every one released.
  explicit FakeRelayBackend(std::size_t line_count) : levels_(line_count, false) {}

  bool set(std::size_t index, bool energised) override {
    if (fail_writes) {
      errno = EIO;
      return false;
    }
    levels_.at(index) = energised;
    writes_.push_back({index, energised});
    return true;
  }

  bool fail_writes = false;  // every write fails (EIO) while set
  [[nodiscard]] bool level(std::size_t index) const { return levels_.at(index); }
  [[nodiscard]] const std::vector<Write>& writes() const { return writes_; }

 private:
  std::vector<bool> levels_;
  std::vector<Write> writes_;
};

}  // namespace plinth::firmware
