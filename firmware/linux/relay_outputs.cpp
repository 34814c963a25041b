#include "relay_outputs.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace plinth::firmware {

bool relay_energised(Relay relay, monitor::AlarmLevel shown, monitor::AlarmLevel latched,
                     bool fault) {
  using monitor::AlarmLevel;
  if (shown == AlarmLevel::kFault) return false;
  if (relay == Relay::kFault) return !fault;
  // Relay order = level order - 1: advisory opens at advisory, warning at warning, ...
  const int level = static_cast<int>(relay) + 1;
  const int reached = std::max(static_cast<int>(shown),
                               latched == AlarmLevel::kFault ? 0 : static_cast<int>(latched));
  return reached < level;
}

RelayOutputs::RelayOutputs(const RelaySettings& settings, std::unique_ptr<RelayBackend> backend)
    : backend_(std::move(backend)) {
  int next = 0;
  for (std::size_t i = 0; i < kRelayCount; ++i) {
    wired_index_[i] = settings.lines[i].offset >= 0 ? next++ : -1;
  }
}

void RelayOutputs::update(monitor::AlarmLevel shown, monitor::AlarmLevel latched, bool fault) {
  for (std::size_t i = 0; i < kRelayCount; ++i) {
    if (wired_index_[i] < 0) continue;
    const bool want = relay_energised(static_cast<Relay>(i), shown, latched, fault);
    if (want == energised_[i]) continue;
    ++writes_;
    if (backend_->set(static_cast<std::size_t>(wired_index_[i]), want)) {
      energised_[i] = want;
    } else if (write_errors_++ == 0) {  // once: the loop must not flood stderr
      std::fprintf(stderr, "plinth-monitor: warning: relay %s: write failed: %s\n", kRelayNames[i],
                   std::strerror(errno));
    }
  }
}

}  // namespace plinth::firmware
