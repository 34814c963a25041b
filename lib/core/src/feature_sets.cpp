// The scene feature sets compiled in (build_options.h, PLINTH_CORE_FEATURE_MASK) and the binding
// of their event logic: the only place that instantiates EventLogic<F>, so that a set left out
// leaves its code out. An image compiles this file again for its scenes' sets alone
// (plinth_core_feature_sets, lib/core/CMakeLists.txt).
#include "feature_sets.h"

#include <cstddef>

#include "build_options.h"
#include "event_logic.h"

namespace plinth {

namespace {

// The feature sets (scene.h, Features) as the build names them: the base (ground, base,
// base_stops) times the contact (no_sliding, sliding, support_edge, sliding_stops).
constexpr std::size_t kFeatureSetCount = 12;
constexpr std::size_t feature_set_index(const Features& f) {
  const std::size_t base = !f.base ? 0 : (!f.base_stops ? 1 : 2);
  const std::size_t contact = !f.sliding ? 0 : (f.support_edge ? 2 : (f.sliding_stops ? 3 : 1));
  return 4 * base + contact;
}
// Where the sets were chosen, for the refusal: the build's option, or an image's own list.
#ifndef PLINTH_CORE_FEATURE_SETS_SOURCE
#define PLINTH_CORE_FEATURE_SETS_SOURCE "PLINTH_CORE_FEATURE_SETS"
#endif
constexpr bool compiled_in_at(std::size_t index) {
  return ((PLINTH_CORE_FEATURE_MASK >> index) & 1) != 0;
}
constexpr bool compiled_in(const Features& f) { return compiled_in_at(feature_set_index(f)); }

// The refusal of each set left out. A set compiled in is never refused: no message (up to 91
// bytes of flash each on a microcontroller).
#define PLINTH_LEFT_OUT(index, set) \
  compiled_in_at(index)            \
      ? ""                         \
      : "is " set ", a feature set this build leaves out (" PLINTH_CORE_FEATURE_SETS_SOURCE ")"
constexpr const char* kFeatureSetLeftOut[kFeatureSetCount] = {
    PLINTH_LEFT_OUT(0, "ground+no_sliding"),
    PLINTH_LEFT_OUT(1, "ground+sliding"),
    PLINTH_LEFT_OUT(2, "ground+support_edge"),
    PLINTH_LEFT_OUT(3, "ground+sliding_stops"),
    PLINTH_LEFT_OUT(4, "base+no_sliding"),
    PLINTH_LEFT_OUT(5, "base+sliding"),
    PLINTH_LEFT_OUT(6, "base+support_edge"),
    PLINTH_LEFT_OUT(7, "base+sliding_stops"),
    PLINTH_LEFT_OUT(8, "base_stops+no_sliding"),
    PLINTH_LEFT_OUT(9, "base_stops+sliding"),
    PLINTH_LEFT_OUT(10, "base_stops+support_edge"),
    PLINTH_LEFT_OUT(11, "base_stops+sliding_stops"),
};
#undef PLINTH_LEFT_OUT

// Binds EventLogic<F> when the build has F (validate_feature_set refused the scene otherwise).
template <Features F>
void bind_features(Simulator& sim, const SolverSettings& settings) {
  if constexpr (compiled_in(F)) {
    internal::EventLogic<F>::bind_to(sim, settings);
  } else {
    (void)sim;
    (void)settings;
  }
}

template <bool kBase, bool kBaseStops>
void bind_for_friction(Simulator& sim, const Features& f, const SolverSettings& settings) {
  if (!f.sliding) {
    bind_features<Features{kBase, kBaseStops, false, false, false}>(sim, settings);
  } else if (f.support_edge) {
    bind_features<Features{kBase, kBaseStops, true, true, false}>(sim, settings);
  } else if (f.sliding_stops) {
    bind_features<Features{kBase, kBaseStops, true, false, true}>(sim, settings);
  } else {
    bind_features<Features{kBase, kBaseStops, true, false, false}>(sim, settings);
  }
}

}  // namespace

Error validate_feature_set(const Scene& scene) {
  const Features f = features_of(scene);
  if (compiled_in(f)) return ok_error();
  return {ErrorCode::kInconsistent, "scene", kFeatureSetLeftOut[feature_set_index(f)]};
}

namespace internal {

void bind_event_logic(Simulator& sim, const Features& f, const SolverSettings& settings) {
  if (!f.base) {
    bind_for_friction<false, false>(sim, f, settings);
  } else if (!f.base_stops) {
    bind_for_friction<true, false>(sim, f, settings);
  } else {
    bind_for_friction<true, true>(sim, f, settings);
  }
}

}  // namespace internal

}  // namespace plinth
