// Errors of the freestanding core: plain values, no exceptions, no allocation.
#pragma once

#include <cstdint>

namespace plinth {

enum class ErrorCode : std::uint8_t {
  kOk = 0,
  kNotFinite,     // NaN or infinity where a number is required
  kOutOfRange,    // a finite value outside its physical range
  kInconsistent,  // values that are each fine but do not fit together
};

// `field` names the scene or setting field at fault with its canonical key (for example
// "block.eccentricity"); `reason` says what is wrong in a short English phrase. Both point to
// string literals, so an Error can be copied and stored freely.
struct Error {
  ErrorCode code = ErrorCode::kOk;
  const char* field = "";
  const char* reason = "";
  // the bound that was passed, in the field's unit, where there is one; reported, not computed
  // with: double whatever Real is (real.h)
  double limit = 0.0;

  [[nodiscard]] constexpr bool ok() const { return code == ErrorCode::kOk; }
};

[[nodiscard]] constexpr Error ok_error() { return Error{}; }

}  // namespace plinth

// Returns the Error of `expr` from the enclosing function when it is not ok (Pigweed's PW_TRY).
#define PLINTH_TRY(expr)                                                             \
  do {                                                                               \
    if (const ::plinth::Error plinth_try_error_ = (expr); !plinth_try_error_.ok()) { \
      return plinth_try_error_;                                                      \
    }                                                                                \
  } while (false)
