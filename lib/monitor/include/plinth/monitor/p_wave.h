// The on-site P-wave stage: from the first seconds of an earthquake at the box's own ground
// sensor, a probability that the statue collapses in the S waves still to come. Its filters,
// trigger states, prediction and probability: docs/pwave.md, "The stage in detail".
// Freestanding: no heap, no exceptions; every tunable named with its unit, checked by validate().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/fragility.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/monitor/optional_part.h"  // kPWaveStageBuiltIn

namespace plinth::monitor {

enum class PWaveChannel : std::uint8_t { kVertical = 0, kHorizontal = 1 };

inline constexpr NameTable<PWaveChannel, 2> kPWaveChannelNames{{{
    {PWaveChannel::kVertical, "vertical"},
    {PWaveChannel::kHorizontal, "horizontal"},
}}};

// One point of the prediction's table.
struct PWavePredictorPoint {
  Time window_s = 0.0;    // s since the candidate's start
  Real ln_pga_over_pa = 0.0;  // c0: ln(PGA / Pa) at tau_c = 1 s, dimensionless
  Real tau_c_exponent = 0.0;  // c1: the exponent of tau_c / 1 s, dimensionless
  Real sigma_ln = 1.0;        // the prediction's scatter, standard deviation of ln PGA, > 0
};

inline constexpr std::size_t kMaxPWavePredictorPoints = 8;

// The tables fitted by plinth-eval pwave-fit on the bundled calibration records
// (sim/data/records/pwave/, each station's two horizontals with its vertical, scaled to 0.3,
// 0.6 and 1.2 g, at 200 Hz; docs/pwave.md), c1 = 0 (tau_c's exponent, fitted, changed sign
// from window to window: not resolved by five earthquakes):
//   plinth-eval pwave-fit $(tools/pwave-records.sh sim/data/records/pwave) [--channel horizontal]
inline constexpr std::array<PWavePredictorPoint, kMaxPWavePredictorPoints>
    kDefaultVerticalPredictor{{
        {0.5, Real(3.091), Real(0.0), Real(0.649)},
        {1.0, Real(2.749), Real(0.0), Real(0.802)},
        {1.5, Real(2.588), Real(0.0), Real(0.767)},
        {2.0, Real(2.484), Real(0.0), Real(0.749)},
        {2.5, Real(2.290), Real(0.0), Real(0.962)},
        {3.0, Real(2.052), Real(0.0), Real(0.945)},
        {3.5, Real(1.877), Real(0.0), Real(1.003)},
        {4.0, Real(1.758), Real(0.0), Real(1.023)},
    }};
inline constexpr std::array<PWavePredictorPoint, kMaxPWavePredictorPoints>
    kDefaultHorizontalPredictor{{
        {0.5, Real(3.357), Real(0.0), Real(0.821)},
        {1.0, Real(3.082), Real(0.0), Real(0.858)},
        {1.5, Real(2.750), Real(0.0), Real(0.943)},
        {2.0, Real(2.375), Real(0.0), Real(1.079)},
        {2.5, Real(2.004), Real(0.0), Real(1.041)},
        {3.0, Real(1.566), Real(0.0), Real(0.953)},
        {3.5, Real(1.227), Real(0.0), Real(0.806)},
        {4.0, Real(1.076), Real(0.0), Real(0.757)},
    }};

// The table fitted for a channel.
[[nodiscard]] constexpr const std::array<PWavePredictorPoint, kMaxPWavePredictorPoints>&
default_predictor(PWaveChannel channel) {
  return channel == PWaveChannel::kHorizontal ? kDefaultHorizontalPredictor
                                              : kDefaultVerticalPredictor;
}

struct PWaveSettings {
  bool enabled = true;
  Time sample_period_s = 0.001;  // s, of the conditioned stream
  PWaveChannel channel = PWaveChannel::kVertical;
  Real highpass_hz = Real(0.075);  // Hz: below it, drift (Wu & Kanamori's 0.075 Hz)
  // Hz: above it, the building (footsteps, doors, traffic: 5 Hz and up) and not the statue
  // (a rocking block answers to the long periods); docs/pwave.md measured the choice.
  Real lowpass_hz = 3.0;
  Time sta_s = 0.25;            // s, short-term average of a^2
  Time lta_s = 10.0;            // s, long-term average of a^2
  Real trigger_ratio = 8.0;     // STA / LTA (of a^2) that starts a candidate, > 1
  Real detrigger_ratio = 2.0;   // STA / LTA below which an excitation ends, < trigger_ratio
  Real noise_floor_m_s2 = Real(0.002);   // m/s2 rms: the LTA never counts below it
  Real min_amplitude_m_s2 = Real(0.05);  // m/s2 rms: the STA must reach it too
  Time confirm_s = 0.5;         // s after the candidate's start: judged
  // s: the latest a retry may start after its excitation's first candidate; a later one is
  // inside the shaking, the S waves. The bundled records' triggers before their strong motion
  // came at most 1.7 s after it (docs/pwave.md): the next half second up.
  Time max_retry_s = 2.0;
  Time min_tau_p_s = 0.3;       // s: shorter is a floor, a door or traffic (docs/pwave.md)
  Time max_tau_c_s = 10.0;      // s: longer is drift (a tilt, a step)
  Real min_vertical_ratio = Real(0.5);  // vertical channel: peak |a_z| / peak |a_h| at least
  Real s_wave_ratio = Real(1.5);        // vertical channel: peak |a_h| / peak |a_z| closing it
  Time max_window_s = 4.0;      // s: the longest window
  Time hold_s = 30.0;           // s: the probability is held this long after the window
  // The channel's own table (default_predictor(channel)): a horizontal channel's Pa is not a
  // vertical one's.
  std::array<PWavePredictorPoint, kMaxPWavePredictorPoints> predictor = kDefaultVerticalPredictor;
  std::size_t predictor_points = kDefaultVerticalPredictor.size();  // 1..kMaxPWavePredictorPoints
  bool fragility_known = false;  // the scene file's [fragility] was given
  LognormalFragility fragility;  // the statue's, PGA in g (median_g > 0, beta >= 0)
};

// Checks the settings; the Error names the field at fault ("pwave.lowpass_hz", ...): periods,
// durations (max_retry_s too) and amplitudes positive and finite; highpass_hz < lowpass_hz <
// half the sample rate; trigger_ratio > 1; 0 < detrigger_ratio < trigger_ratio; confirm_s <=
// max_window_s; min_tau_p_s < max_tau_c_s; the ratios positive; the table's windows
// increasing, its sigmas positive; the fragility's median positive and its beta not negative
// when known.
[[nodiscard]] Error validate(const PWaveSettings& settings);

enum class PWaveState : std::uint8_t { kIdle = 0, kCandidate, kWindow, kHolding };

enum class PWaveRejection : std::uint8_t {
  kNone = 0,
  kPeriodShort,  // tau_p below min_tau_p_s
  kPeriodLong,   // tau_c above max_tau_c_s
  kHorizontal,   // peak |a_z| below min_vertical_ratio * peak |a_h|
  kNotAfterQuiet,  // would start over max_retry_s after its excitation's first candidate
};

enum class PWaveWindowEnd : std::uint8_t { kNone = 0, kMaxWindow, kSWave };

inline constexpr NameTable<PWaveState, 4> kPWaveStateNames{{{
    {PWaveState::kIdle, "idle"},
    {PWaveState::kCandidate, "candidate"},
    {PWaveState::kWindow, "window"},
    {PWaveState::kHolding, "holding"},
}}};

inline constexpr NameTable<PWaveRejection, 5> kPWaveRejectionNames{{{
    {PWaveRejection::kNone, "none"},
    {PWaveRejection::kPeriodShort, "period too short"},
    {PWaveRejection::kPeriodLong, "period too long"},
    {PWaveRejection::kHorizontal, "not vertical enough"},
    {PWaveRejection::kNotAfterQuiet, "not after quiet"},
}}};

inline constexpr NameTable<PWaveWindowEnd, 3> kPWaveWindowEndNames{{{
    {PWaveWindowEnd::kNone, "none"},
    {PWaveWindowEnd::kMaxWindow, "max_window"},
    {PWaveWindowEnd::kSWave, "s_wave"},
}}};

// The stage after a sample. Times are s since the stage started (or restarted): the sample's
// index (0 for the first) times sample_period_s.
struct PWaveStatus {
  PWaveState state = PWaveState::kIdle;
  Real sta_lta = 0.0;  // STA / max(LTA, floor^2), of a^2
  std::uint64_t candidates = 0;
  std::uint64_t triggers = 0;
  std::uint64_t rejected_short = 0;       // candidates rejected for a short tau_p
  std::uint64_t rejected_long = 0;        // ... a long tau_c
  std::uint64_t rejected_horizontal = 0;  // ... too little vertical motion
  // Excitations refused: loud for over max_retry_s since their first candidate (each counted
  // once; no candidate of theirs is counted in `candidates`).
  std::uint64_t rejected_not_after_quiet = 0;
  PWaveRejection last_rejection = PWaveRejection::kNone;
  Time excitation_onset_s = 0.0;  // the latest excitation's first candidate (once candidates > 0)
  // The latest candidate that became a trigger (valid once triggers > 0):
  Time onset_s = 0.0;          // its first sample
  Time window_s = 0.0;         // W: the window so far (held after it closed)
  PWaveWindowEnd window_end = PWaveWindowEnd::kNone;
  Real pa_m_s2 = 0.0;          // Pa, peak |a| of the trigger channel
  Real pv_m_s = 0.0;           // Pv, peak |v|
  Real pd_m = 0.0;             // Pd, peak |d|
  Real tau_c_s = 0.0;          // tau_c over the window
  Real tau_p_s = 0.0;          // tau_p over the window
  Real horizontal_m_s2 = 0.0;  // peak |a_h|, the horizontal pair's magnitude
  Real predicted_pga_g = 0.0;  // the latest prediction, g
  Real sigma_ln = 0.0;         // its scatter
  Real probability = 0.0;      // of collapse, the event's highest so far; 0 when idle
};

namespace detail {
// A 2nd-order state-variable filter, topology-preserving transform (Zavalishin, "The Art of VA
// Filter Design", ch. 4): high, band and low outputs of s^2, w s and w^2 over s^2 + k w s + w^2
// (k = sqrt 2: Butterworth), w prewarped to the corner.
struct StateVariableFilter {
  Real g = 0.0;       // tan(pi fc T)
  Real k = 0.0;       // damping, 1/Q
  Real h = 0.0;       // 1 / (1 + k g + g^2)
  Real w = 0.0;       // the prewarped corner, 2 g / T, rad/s
  Real s1 = 0.0;
  Real s2 = 0.0;
  struct Out {
    Real low = 0.0;
    Real band = 0.0;
    Real high = 0.0;
  };
  void design(Real corner_hz, Time period_s);
  Out step(Real x);
  void clear() { s1 = s2 = Real(0); }
};

// One channel: its band-passed acceleration, and its velocity and displacement integrated
// from rest at the last start_integration().
struct PWaveChannelFilter {
  StateVariableFilter lowpass;
  StateVariableFilter highpass;      // -> high: band-passed a
  StateVariableFilter velocity;      // a -> band / w: v
  StateVariableFilter displacement;  // v -> band / w: d
  Real a = 0.0;
  Real v = 0.0;
  Real d = 0.0;
  void design(const PWaveSettings& s);
  void step_acceleration(Real x);  // a
  void step_integration();         // v and d from a
  void start_integration();        // v and d from rest: the next step_integration() is the first
  void clear();
};
}  // namespace detail

class PWaveStage {
 public:
  PWaveStage() = default;

  // Fails on invalid settings (the Error names the field); `out` is then left untouched.
  [[nodiscard]] static Error create(const PWaveSettings& settings, PWaveStage& out);

  // One conditioned sample (statue frame, m/s2, z = v_G''). A non-finite sample is refused:
  // nothing changes but the refused count.
  const PWaveStatus& update(const Vector3r& ground_m_s2);
  // Forgets everything but the counters (after a gap in the stream: the filters' state does
  // not connect across it). Times start again from 0.
  void restart();

  [[nodiscard]] const PWaveStatus& status() const { return status_; }
  [[nodiscard]] const PWaveSettings& settings() const { return settings_; }
  [[nodiscard]] std::uint64_t refused() const { return refused_; }

  // The prediction's table at window W (interpolated), for tests and tools.
  [[nodiscard]] PWavePredictorPoint predictor_at(Time window_s) const;
  // ln PGA (PGA in m/s2) predicted from Pa (m/s2) and tau_c (s) at window W.
  [[nodiscard]] Real predicted_ln_pga(Real pa_m_s2, Real tau_c_s, Time window_s) const;
  // The probability of collapse for a predicted PGA (g) with scatter sigma_ln.
  [[nodiscard]] Real collapse_probability(Real predicted_pga_g, Real sigma_ln) const;

 private:
  void start_or_refuse_candidate();
  void start_candidate();
  void judge_candidate();
  void update_window();
  void close_window(PWaveWindowEnd end);
  [[nodiscard]] Real window_tau_c() const;
  [[nodiscard]] Real window_tau_p() const;

  PWaveSettings settings_;
  Real sta_gain_ = 0.0;  // per-sample gains of the exponential averages
  Real lta_gain_ = 0.0;
  Real floor_energy_ = 0.0;
  Real min_energy_ = 0.0;
  std::int64_t confirm_samples_ = 0;
  std::int64_t max_retry_samples_ = 0;
  std::int64_t max_window_samples_ = 0;
  std::int64_t hold_samples_ = 0;

  std::array<detail::PWaveChannelFilter, 3> filters_{};  // x, y, z
  Real sta_ = 0.0;
  Real lta_ = 0.0;
  std::int64_t sample_ = 0;        // samples since start or restart
  std::int64_t state_since_ = 0;   // sample the current state began
  // The excitation: from a candidate out of quiet to the next idle sample with STA below
  // detrigger_ratio * LTA.
  bool excited_ = false;
  bool excitation_refused_ = false;   // counted in rejected_not_after_quiet
  std::int64_t excitation_since_ = 0;  // its first candidate's sample
  // The window since the candidate's start.
  Real sum_d2_ = 0.0;
  Real sum_v2_ = 0.0;
  Real sum_a2_ = 0.0;
  Real peak_a_ = 0.0;
  Real peak_v_ = 0.0;
  Real peak_d_ = 0.0;
  Real peak_h_ = 0.0;
  PWaveStatus status_;
  std::uint64_t refused_ = 0;
};

// The stage's settings and status as the monitor's configuration and status hold them: nothing
// in a build without the stage (kPWaveStageBuiltIn false; the box file's reader refuses a
// [pwave] table there).
using PWaveConfig = OptionalPart<PWaveSettings, kPWaveStageBuiltIn>;
using PWaveStatusField = OptionalPart<PWaveStatus, kPWaveStageBuiltIn>;
// The stage's default settings, off (a box without a [pwave] table).
[[nodiscard]] constexpr PWaveConfig pwave_off() {
  PWaveSettings off;
  off.enabled = false;
  return part_if<kPWaveStageBuiltIn>(off);
}

}  // namespace plinth::monitor
