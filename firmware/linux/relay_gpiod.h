// The relays' lines through the Linux GPIO character device, with libgpiod (v1.6 API, Debian
// 12's libgpiod-dev). Host code: may allocate and throw.
#pragma once

#include <memory>

#include "relay_outputs.h"

namespace plinth::firmware {

// Opens settings.chip and requests its wired lines as outputs, each released (de-energised:
// low, or high when active-low) from the start, for as long as the backend lives; the kernel
// releases them when the process ends, however it ends. Throws host::InputError naming the
// chip and the relay: no such chip, an offset beyond its lines, a line another program holds.
[[nodiscard]] std::unique_ptr<RelayBackend> open_gpiod_relays(const RelaySettings& settings);

}  // namespace plinth::firmware
