// Checks and conversions shared by the monitor components' settings (private to plinth_monitor).
#pragma once

#include <cmath>
#include <cstdint>
#include <initializer_list>

#include "plinth/core/checks.h"
#include "plinth/core/error.h"
#include "plinth/core/fragility.h"
#include "plinth/core/real.h"

namespace plinth::monitor::detail {

// Longest duration a setting may name, s (11.6 days): keeps every duration exact to the
// nanosecond in an int64 and catches a value typed in the wrong unit.
inline constexpr Time kMaxDurationS = 1e6;

inline constexpr std::int64_t kNanosecondsPerSecond = 1'000'000'000;

// A duration setting: finite, within [0, kMaxDurationS], and above zero unless `zero_allowed`.
[[nodiscard]] inline Error check_duration(Time seconds, const char* field, bool zero_allowed) {
  if (!std::isfinite(seconds)) {
    return {ErrorCode::kNotFinite, field, "must be a finite number of seconds"};
  }
  if (seconds < 0.0 || (!zero_allowed && seconds <= 0.0)) {
    return {ErrorCode::kOutOfRange, field,
            zero_allowed ? "must not be negative" : "must be greater than zero", 0.0};
  }
  if (seconds > kMaxDurationS) {
    return {ErrorCode::kOutOfRange, field, "must not exceed 1e6 s", kMaxDurationS};
  }
  return ok_error();
}

// A statue's fragility (the scene's [fragility], "fragility.median_g" and "fragility.beta"):
// median_g finite and > 0, beta finite and >= 0 (0: a step at the median).
[[nodiscard]] inline Error check_fragility(const LognormalFragility& fragility) {
  PLINTH_TRY(check_positive(fragility.median_g, "fragility.median_g"));
  if (!std::isfinite(fragility.beta)) {
    return {ErrorCode::kNotFinite, "fragility.beta", "must be finite"};
  }
  if (fragility.beta < Real(0)) {
    return {ErrorCode::kOutOfRange, "fragility.beta", "must not be negative", 0.0};
  }
  return ok_error();
}

// The first failed check of a list, in order; ok when all pass. Every check is evaluated, so
// list only checks that are safe on any input.
[[nodiscard]] inline Error first_error(std::initializer_list<Error> checks) {
  for (const Error& e : checks) {
    if (!e.ok()) return e;
  }
  return ok_error();
}

// Seconds (already checked by check_duration) to the nearest nanosecond.
[[nodiscard]] inline std::int64_t to_ns(Time seconds) {
  const Time ns = seconds * static_cast<Time>(kNanosecondsPerSecond);
  return static_cast<std::int64_t>(std::llround(ns));
}

}  // namespace plinth::monitor::detail
