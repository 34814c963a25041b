// Private to plinth_core: build-time choices for small targets (lib/core/CMakeLists.txt,
// docs/microcontroller.md). Every stepper and flattened intervals by default; a microcontroller
// keeps the estimator's stepper alone and calls what the host inlines, to fit its flash.
#pragma once

#ifndef PLINTH_CORE_RK4_ONLY
#define PLINTH_CORE_RK4_ONLY 0
#endif
// PLINTH_FLATTENED_OUT: a cold path a flattened interval calls (inlined, its code would crowd
// the hot path's registers); inlined where nothing is flattened (less flash).
#if !defined(PLINTH_CORE_FLATTEN) || PLINTH_CORE_FLATTEN
#define PLINTH_FLATTEN [[gnu::flatten]]
#define PLINTH_FLATTENED_OUT [[gnu::noinline, gnu::cold]]
#define PLINTH_CORE_ONE_INTERVAL 0
#else
#define PLINTH_FLATTEN
#define PLINTH_FLATTENED_OUT
// Nothing flattened, one interval for every phase kernel (kernels::Erased, step_interval.h).
#define PLINTH_CORE_ONE_INTERVAL 1
#endif

// The scene feature sets compiled in (PLINTH_CORE_FEATURE_SETS): bit 4 * base + contact of
// feature_set_index (simulator.cpp); every set by default. A scene of a set left out is refused
// by Simulator::create.
#ifndef PLINTH_CORE_FEATURE_MASK
#define PLINTH_CORE_FEATURE_MASK 0xFFF
#endif
