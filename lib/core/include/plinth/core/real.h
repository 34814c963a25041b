// The scalar of the model's arithmetic, a build-time choice (CMake cache variable PLINTH_REAL):
// double by default (every host build), float for a microcontroller whose FPU is single precision
// (the Cortex-M4F: docs/microcontroller.md). The state, the scene's derived constants, flows,
// steppers, guards, resets, the propagator, the risk and lib/monitor's arithmetic are Real.
//
// Time is not: plinth::Time is double in both builds. Float's spacing at 2048 s (34 min) is
// 2048 * 2^-23 = 0.24 ms, a whole 0.25 ms step; the solver's time is step_count * step, which a
// double keeps to a nanosecond for centuries. The offsets inside one step (stage times, located
// events) are Real, added to the step's start explicitly; a double add per stage is the cost.
// A quiet step takes no other double arithmetic than its end time: the ground's interpolation
// weight is the offset into the sample interval (a double difference) divided in Real, and a
// whole step is known to end at its end time (no double check of t0 + h).
#pragma once

#include <Eigen/Core>
#include <limits>

#ifndef PLINTH_REAL_FLOAT
#define PLINTH_REAL_FLOAT 0
#endif

namespace plinth {

#if PLINTH_REAL_FLOAT
using Real = float;
#else
using Real = double;
#endif

// Eigen's fixed-size types in Real (Eigen's d suffix: r).
using Vector2r = Eigen::Matrix<Real, 2, 1>;
using Vector3r = Eigen::Matrix<Real, 3, 1>;
using Matrix3r = Eigen::Matrix<Real, 3, 3>;
using Matrix4r = Eigen::Matrix<Real, 4, 4>;

// Seconds since the start of a run: double whatever Real is (above).
using Time = double;

// Tolerances chosen for double, scaled to Real's epsilon (2.2e-16 double, 1.2e-7 float). Each is
// the double value in a double build (bit for bit what it was) and a small multiple of epsilon in
// a float build, where the double value lies below float's resolution.
namespace real_tolerance {
inline constexpr Real kEpsilon = std::numeric_limits<Real>::epsilon();
inline constexpr bool kSingle = sizeof(Real) < sizeof(double);
// Events are located in time to this fraction of the step (SolverSettings::event_time_tolerance):
// 1e-10 in double (~5e5 roundings of the step); in float 64 roundings of the step (7.6e-6), the
// closest a float offset inside the step resolves with margin.
inline constexpr Real kEventTime = kSingle ? Real(64) * kEpsilon : Real(1e-10);
// A position "at" a limit (a base stop, the support's edge) within this fraction of the limit:
// 1e-9 and 1e-12 in double; 8 roundings in float (9.5e-7).
inline constexpr Real kAtStop = kSingle ? Real(8) * kEpsilon : Real(1e-9);
inline constexpr Real kAtEdge = kSingle ? Real(8) * kEpsilon : Real(1e-12);
}  // namespace real_tolerance

}  // namespace plinth
