// Internal to plinth_core (tests may include it). Single-precision sin and cos for bounded
// arguments, without libm: newlib's sinf/cosf reduce any argument, up to 3.4e38, by a
// Payne-Hanek reduction (its 2/pi table and multi-word arithmetic are 3.9 KB of a
// microcontroller's flash); every angle the model meets is a block's rotation (within +-pi/2
// until it overturns) or a pulse's phase (within [0, 2 pi]). A float build takes these in place of
// std::sin and std::cos (flows.h, real_sin_cos); a double build keeps libm.
#pragma once

#include <limits>

namespace plinth::internal {

struct FloatSinCos {
  float sin = 0.0F;
  float cos = 1.0F;
};

namespace bounded_trig {

// |x| up to this, rad: the quadrant k = round(x 2 / pi) has at most 13 bits, so k kPio2High and
// k kPio2Middle are exact in float (8 and 11 significant bits). Beyond it (or infinite), NaN.
inline constexpr float kRange = 8192.0F;
// pi / 2 = kPio2High + kPio2Middle + kPio2Low (+1.7e-15): Cody and Waite's reduction.
inline constexpr float kPio2High = 0x1.92p+0F;
inline constexpr float kPio2Middle = 0x1.fb4p-12F;
inline constexpr float kPio2Low = 0x1.4442d2p-24F;
inline constexpr float kTwoOverPi = 0x1.45f306p-1F;
// Rounds to the nearest integer by adding and subtracting 1.5 2^23 (no conversion on the way).
inline constexpr float kRoundingShift = 12582912.0F;

// sin r and cos r for |r| <= pi / 4 by their Taylor series to r^11 and r^12 (the first term left
// out is below 6e-12), in Horner's form.
[[nodiscard]] inline FloatSinCos kernel(float r) {
  const float r2 = r * r;
  const float sin_r =
      r + r * r2 *
              (-1.0F / 6.0F +
               r2 * (1.0F / 120.0F + r2 * (-1.0F / 5040.0F +
                                           r2 * (1.0F / 362880.0F + r2 * (-1.0F / 39916800.0F)))));
  const float cos_r =
      1.0F + r2 * (-0.5F + r2 * (1.0F / 24.0F +
                                 r2 * (-1.0F / 720.0F + r2 * (1.0F / 40320.0F +
                                                              r2 * (-1.0F / 3628800.0F +
                                                                    r2 * (1.0F / 479001600.0F))))));
  return {sin_r, cos_r};
}

}  // namespace bounded_trig

// sin x and cos x for |x| <= bounded_trig::kRange: within two roundings of the result and, for
// large |x|, 3e-11 absolute (the reduction's roundings, k kPio2Low mostly); NaN beyond
// the range and for a NaN or infinite x.
[[nodiscard]] inline FloatSinCos bounded_sin_cos(float x) {
  using namespace bounded_trig;
  if (!(x >= -kRange && x <= kRange)) {
    return {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN()};
  }
  const float k = (x * kTwoOverPi + kRoundingShift) - kRoundingShift;
  const float r = ((x - k * kPio2High) - k * kPio2Middle) - k * kPio2Low;
  const FloatSinCos t = kernel(r);
  switch (static_cast<int>(k) & 3) {  // the quadrant (two's complement: -1 & 3 is 3)
    case 0:
      return t;
    case 1:
      return {t.cos, -t.sin};
    case 2:
      return {-t.sin, -t.cos};
    default:
      return {-t.cos, t.sin};
  }
}

}  // namespace plinth::internal
