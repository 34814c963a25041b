// Which statues an ensemble holds: points of a two-level design over the declared uncertainty.
//
// Each uncertain parameter is scaled to z in [-1, 1] (low .. high of its declared range, 0 the
// scene file's nominal value, which need not be the range's middle: see the scene loader). The
// design is the centre (the nominal statue, member 0) and corners:
//   d <= 3       the full factorial, 2^d corners;
//   4 <= d <= 7  an 8-run fraction of resolution III or better (generators D = ABC, E = AB,
//                F = AC, G = BC; for d = 4 resolution IV);
//   8 <= d <= 15 a 16-run fraction of resolution III (base factors A..D and their interactions).
// Corners rather than a star (one parameter off nominal at a time): a fragile statue is
// fragile in several ways at once (slender and eccentric; a base near resonance and lightly
// damped), and only corners put those extremes together. Every column is balanced (as many
// lows as highs) and no two columns are equal, so each parameter's extremes are both present
// and told apart. Freestanding: no heap.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "plinth/core/real.h"

namespace plinth {

inline constexpr int kMaxUncertainParameters = 15;
// Members of the largest design: the centre and 16 corners.
inline constexpr int kMaxDesignPoints = 17;

using DesignPoint = std::array<Real, kMaxUncertainParameters>;  // z_i in [-1, 1]; unused: 0

// The number of points the design of `dimensions` parameters has (0 when dimensions is
// outside [0, kMaxUncertainParameters]).
[[nodiscard]] int design_point_count(int dimensions);

// Writes the design's points to `out` (centre first) and returns their count; 0 when
// `dimensions` is out of range or `out` is too small.
[[nodiscard]] int two_level_design(int dimensions, std::span<DesignPoint> out);

}  // namespace plinth
