// What the host tools accept. A number a user gives (an option, a key, a file's header) is also
// checked for what it implies: solver steps, output rows, bisection steps, a scaled record's
// peak. Each limit is named here with its unit; an error names the option or key, the value and
// the limit ("--dt 1e-20: the run would take 1e+21 solver steps, limit 1e+09"). The table of
// every limit each program enforces: docs/limits.md.
#pragma once

#include <cstdint>
#include <string>

namespace plinth::host {

// Solver steps of one plinth-sim run (about 2 minutes of RK4 on one core).
inline constexpr double kMaxRunSteps = 1e9;
// Solver steps of one simulation of a sweep (a sweep runs thousands of them).
inline constexpr double kMaxSweepSimulationSteps = 1e8;
// Rows of a time history CSV (about 1 GB of text).
inline constexpr double kMaxTimeHistoryRows = 1e7;
// Halvings of the PGA bracket a sweep's bisection may take: --pga-max / --tol <= 2^40.
inline constexpr double kMaxBisectionSteps = 40.0;
// An impulse |I| (Eq 34's initial velocity), m/s: 100 m/s throws any statue far beyond
// overturning.
inline constexpr double kMaxImpulse = 100.0;
// Values along one axis of a sweep grid (--steps), and rows of a whole grid.
inline constexpr double kMaxSweepAxisValues = 1e5;
inline constexpr double kMaxSweepRows = 1e6;
// plinth-sweep --jobs: threads.
inline constexpr int kMaxJobs = 256;
// Peak ground acceleration after --pga or --scale, g: no earthquake comes near it, and it keeps
// every product of the solver finite.
inline constexpr double kMaxScaledPeakG = 100.0;
// plinth-replay with a candump log as input holds its sensor frames in memory: at most this
// many (3 h of one node at 1000 Hz), and at most this many lines read in all.
inline constexpr double kMaxReplayLogFrames = 1e7;
inline constexpr double kMaxReplayLogLines = 1e8;
// plinth-replay --speed: slowest and fastest factor of real time ("max" means no pacing).
inline constexpr double kMinReplaySpeed = 1e-3;
inline constexpr double kMaxReplaySpeed = 1e6;

// A number as messages show it: "%.<digits>g", e.g. "1e-20", "0.001".
[[nodiscard]] std::string number_text(double value, int digits = 6);

// "<option> <value>": how a message names what the user gave, e.g. "--dt 1e-20".
[[nodiscard]] std::string given(const std::string& option, double value);

// A count of `what` (e.g. "solver steps") that `subject` implies, checked: returns it rounded
// down to a whole number. Throws InputError "<subject>: <doing> <count> <what>, limit <limit>"
// (doing, e.g., "the run would take") when the count is not finite or above `limit`.
[[nodiscard]] std::int64_t bounded_count(double count, double limit, const std::string& subject,
                                         const std::string& doing, const std::string& what);

// The factor gamma of a record whose peak is `peak_mps2`, checked: |gamma| * peak must stay
// within kMaxScaledPeakG (with `gravity` for g). `subject` names what gave gamma ("--scale
// 1e308", "--pga 500g"). Throws InputError otherwise.
void check_scaled_peak(double gamma, double peak_mps2, double gravity, const std::string& subject);

}  // namespace plinth::host
