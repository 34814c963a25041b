// Private to plinth_core: the scene feature sets (scene.h, Features) whose event logic is compiled
// in, and its binding to a simulator. Defined in feature_sets.cpp, which the library compiles for
// PLINTH_CORE_FEATURE_SETS; an image may compile its own copy for the sets of its scenes alone
// (plinth_core_feature_sets, lib/core/CMakeLists.txt), which the linker then takes instead.
#pragma once

#include "plinth/core/scene.h"
#include "plinth/core/simulator.h"

namespace plinth::internal {

// Binds the event logic and intervals compiled for exactly the features `f`. The caller has
// checked validate_feature_set (simulator.h): for a set left out, nothing is bound.
void bind_event_logic(Simulator& sim, const Features& f, const SolverSettings& settings);

}  // namespace plinth::internal
