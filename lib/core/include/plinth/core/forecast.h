// The forecast: what happens over the next seconds if the shaking goes on. Each ensemble
// member (a PlanarEstimator on one statue of the declared uncertainty, all fed the same
// measured ground motion) is integrated ahead from its present mode and state under a
// continuation of the measured motion, and the forecast says how many members overturn or fall
// within the horizon, which one first, and when.
//
// Continuation: a window of the latest measured motion (window_s), averaged down to rate_hz and
// repeated to the horizon, times `growth`:
//   kRecentWindow     the window that ends now: the shaking goes on as it is;
//   kStrongestWindow  the most energetic window seen since the start, its energy decaying with
//                     memory_s (a window replaces it when it carries more than what is left):
//                     the shaking may come back as strong as it was, less so as time passes.
//
// Work is spread over the samples: a forecast starts from a snapshot of the members (every
// interval_s at most), then each sample advances it by at most work_steps_per_s / input rate
// solver steps, member after member, so no sample waits for a whole forecast. The outcome is
// published when every member is done; it refers to the snapshot's time.
//
// Freestanding: no heap; sized by kMaxEnsembleMembers, kMaxContinuationSamples and
// kMaxWindowSamples. A Forecaster refers to its own buffers: it stays where it was started.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "plinth/core/ensemble_design.h"
#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/excitation.h"
#include "plinth/core/name_table.h"
#include "plinth/core/simulator.h"
#include "plinth/core/state.h"

// Build-time capacities (lib/core/CMakeLists.txt: cache variables of the same names, public).
#ifndef PLINTH_MAX_ENSEMBLE_MEMBERS
#define PLINTH_MAX_ENSEMBLE_MEMBERS 17
#endif
#ifndef PLINTH_FORECAST
#define PLINTH_FORECAST 1
#endif

namespace plinth {

// Members per axis: the largest two-level design by default; a build may lower it.
inline constexpr int kMaxEnsembleMembers = PLINTH_MAX_ENSEMBLE_MEMBERS;
static_assert(kMaxEnsembleMembers >= 1 && kMaxEnsembleMembers <= kMaxDesignPoints);
// A build without the forecast (a microcontroller's: its buffers are ~68 KB per axis) refuses
// forecast.enabled; its Forecaster holds no buffers.
inline constexpr bool kForecastBuiltIn = PLINTH_FORECAST != 0;
// The continuation's samples (horizon_s * rate_hz + 1) and the window's (window_s * rate_hz).
inline constexpr int kMaxContinuationSamples = kForecastBuiltIn ? 2049 : 1;
inline constexpr int kMaxWindowSamples = kForecastBuiltIn ? 1024 : 1;

enum class Continuation : std::uint8_t { kRecentWindow = 0, kStrongestWindow = 1 };
inline constexpr NameTable<Continuation, 2> kContinuationNames{{{
    {Continuation::kRecentWindow, "recent_window"},
    {Continuation::kStrongestWindow, "strongest_window"},
}}};

struct ForecastSettings {
  bool enabled = true;
  Continuation continuation = Continuation::kRecentWindow;  // docs/forecast.md: it won
  double horizon_s = 4.0;   // s, (0, 10]: how far ahead
  double window_s = 2.0;    // s: the measured motion repeated, at least 0.5 s
  double growth = 1.0;      // the continuation is the window times this, in [0.5, 4]
  double memory_s = 10.0;   // s, > 0: kStrongestWindow's energy decay time constant
  double interval_s = 0.25;  // s, > 0: a forecast starts at most this often
  double rate_hz = 200.0;   // Hz, [50, 1000]: the continuation's rate (at most the input's)
  int steps_per_period = 2;  // solver steps per continuation sample, 1..16
  // Forecast solver steps per second of input at most, >= 1000: bounds the work per sample.
  double work_steps_per_s = 200000.0;
};

// Checks the settings against the input's sample rate; the Error names the field
// ("forecast.horizon_s", ...).
[[nodiscard]] Error validate(const ForecastSettings& settings, double input_rate_hz);

struct ForecastOutcome {
  bool valid = false;          // a forecast has completed since the start
  double start_time_s = 0.0;   // estimator time of the snapshot it started from, s
  int members = 0;
  // Members that overturn or fall within the horizon, or lift off (the model ends there and
  // cannot say they stand: counted as collapsing, the safe side).
  int collapsing = 0;
  double probability = 0.0;    // collapsing / members
  int worst_member = -1;       // the member that collapses first; -1: none does
  std::uint32_t collapsing_members = 0;  // bit m: member m collapses within the horizon
  double collapse_in_s = -1.0;  // s from start_time_s to that collapse; -1: none
  // Each member's, s from start_time_s (read where collapsing_members has its bit).
  std::array<float, kMaxEnsembleMembers> member_collapse_in_s{};
};

class Forecaster {
 public:
  Forecaster() = default;
  Forecaster(const Forecaster&) = delete;  // the running simulator refers to the buffers
  Forecaster& operator=(const Forecaster&) = delete;

  [[nodiscard]] Error start(const ForecastSettings& settings, double input_rate_hz);
  // Forgets the motion and any forecast (the estimators started again).
  void reset();

  // The input sample the members just took, at estimator time `time_s`; starts a forecast
  // when one is due and does this sample's share of the work.
  void on_sample(GroundAcceleration sample, double time_s,
                 std::span<const PlanarEstimator> members);

  [[nodiscard]] const ForecastOutcome& latest() const { return latest_; }
  [[nodiscard]] bool running() const { return member_ < members_; }
  [[nodiscard]] const ForecastSettings& settings() const { return settings_; }
  // Solver steps taken by forecasts since the start (for the cost measurements).
  [[nodiscard]] std::int64_t steps_taken() const { return steps_taken_; }

 private:
  struct Snapshot {
    Mode mode;
    State state = State::Zero();
    const Scene* scene = nullptr;
  };

  void push_window(GroundAcceleration averaged);
  [[nodiscard]] double window_energy() const;
  void begin(double time_s, std::span<const PlanarEstimator> members);
  void fill_continuation();
  void start_member();
  void finish_member(bool collapsed, double time_s);
  void work(double step_budget);

  ForecastSettings settings_;
  bool started_ = false;
  int decimation_ = 1;        // input samples averaged into one window sample
  double rate_hz_ = 200.0;    // the window's effective rate
  int window_length_ = 0;     // samples
  int continuation_length_ = 0;
  double step_s_ = 0.0;
  std::int64_t horizon_steps_ = 0;
  double budget_per_sample_ = 0.0;

  // Input averaging.
  GroundAcceleration sum_{};
  int summed_ = 0;
  // The recent window (a ring) and the strongest one (oldest first).
  std::array<GroundAcceleration, kMaxWindowSamples> window_{};
  int window_next_ = 0;
  int window_count_ = 0;
  std::array<GroundAcceleration, kMaxWindowSamples> strongest_{};
  double strongest_energy_ = 0.0;  // at strongest_time_s_ (decays from there)
  double strongest_time_s_ = 0.0;
  bool have_strongest_ = false;

  // The forecast under way.
  std::array<double, kMaxContinuationSamples> horizontal_{};
  std::array<double, kMaxContinuationSamples> vertical_{};
  std::array<Snapshot, kMaxEnsembleMembers> snapshots_{};
  int members_ = 0;
  int member_ = 0;  // the member being integrated; members_: none
  Simulator simulator_;
  std::int64_t member_steps_ = 0;
  double begin_time_s_ = 0.0;
  double last_begin_s_ = 0.0;
  bool ever_begun_ = false;
  double carry_ = 0.0;  // fractional step budget carried to the next sample
  ForecastOutcome building_;
  ForecastOutcome latest_;
  std::int64_t steps_taken_ = 0;
};

}  // namespace plinth
