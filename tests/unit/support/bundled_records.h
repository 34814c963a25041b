#pragma once
// The bundled records the suites replay, read with lib/host's reader (WITH_HOST_READERS).
#include <string>

#include "plinth/core/scene.h"
#include "plinth/host/record_io.h"
#include "test_paths.h"

namespace plinth::testing {

// Irpinia 1980, Brienza, component 000 (sim/data/records/SOURCES.md).
inline host::Record brienza() {
  return host::read_at2(kSource + "/sim/data/records/irpinia1980_brienza_000.AT2",
                        kStandardGravity);
}

}  // namespace plinth::testing
