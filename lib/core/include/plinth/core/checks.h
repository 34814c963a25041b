// Checks a scene's or a setting's field makes of its value, each returning the Error that names
// the field (error.h). Shared by lib/core's scene and lib/monitor's settings. Freestanding.
#pragma once

#include <cmath>

#include "plinth/core/error.h"
#include "plinth/core/real.h"

namespace plinth {

// A finite, strictly positive quantity in the field's unit.
[[nodiscard]] inline Error check_positive(Real value, const char* field) {
  if (!std::isfinite(value)) return {ErrorCode::kNotFinite, field, "must be a finite number"};
  if (value <= Real(0)) return {ErrorCode::kOutOfRange, field, "must be greater than zero"};
  return ok_error();
}

}  // namespace plinth
