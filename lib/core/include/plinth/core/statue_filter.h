// The statue sensor's use: the ensemble's members weighted by how well each explains the
// statue's measured rotation, the phase from the measurement, sliding from its accelerometer,
// and whether the ground sensors corroborate it. The method: docs/statue-filter.md.
// Freestanding: no heap.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/ensemble.h"
#include "plinth/core/error.h"
#include "plinth/core/excitation.h"
#include "plinth/core/forecast.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/core/risk.h"
#include "plinth/core/state.h"

#ifndef PLINTH_STATUE_SENSOR
#define PLINTH_STATUE_SENSOR 1
#endif

namespace plinth {

// A build without the statue sensor (a microcontroller's with 64 KB of flash: its filter takes
// about 10 KB) refuses one in its settings; the monitor's code for it is left out.
inline constexpr bool kStatueSensorBuiltIn = PLINTH_STATUE_SENSOR != 0;

// Each tunable that decides how far the sensor may lower the risk has bounds (validate(); the
// ranges, and why: docs/statue-filter.md, "Bounds").
struct StatueFilterSettings {
  Real rate_noise_rad_s = Real(0.003);  // rad/s: one measured rate's noise, [1e-4, 0.05]
  Real model_tolerance = Real(0.25);   // the members' theta'' holds to this fraction, [0.05, 1]
  Real rest_rate_rad_s = Real(0.02);   // rad/s: |theta'| below this (and the tilt below
  Real rest_tilt_rad = Real(0.002);    // rad: this) is at rest; (0, 0.05] and (0, 0.01]
  double rest_time_s = 0.1;            // s: at rest this long with a small tilt sets theta to 0
  double interval_s = 0.05;            // s: the innovations' interval, [1 sample, 1 s]
  double memory_s = 10.0;              // s: the evidence's forgetting time constant, [1, 600]
  double score_memory_s = 1.0;         // s: the innovations' mean score's time constant
  Real informative_fraction = Real(0.5);  // informative: effective members <= this * members
  Real credible_weight = Real(0.2);       // the risk: reached by members holding this weight
  Real unexplained_score = Real(6);       // mean nu^2 / s^2 of the best member above: unexplained
  Real ruled_out_fraction = Real(0.1);    // weight below this x 1 / members: ruled out
  // Sliding from the accelerometer (docs/statue-filter.md).
  Real acceleration_noise_m_s2 = Real(0.03);  // m/s2 rms: a sample of f less the ground's, noise
  Real acceleration_bias_m_s2 = Real(0.15);   // m/s2: their biases left after the offsets
  Real slide_tolerance = Real(0.15);  // the prediction holds to this fraction of itself, [0, 1)
  double slide_filter_s = 0.05;       // s: the relative acceleration's low-pass, (0, 1]
  double slide_onset_s = 0.05;        // s: above the threshold this long: sliding, (0, 1]
  double slide_end_s = 0.15;          // s: below it this long: stuck again, (0, 1]
  bool slide_on_isolated_base = false;  // the sliding test on an isolated base too
  // Corroboration by the ground sensors (docs/statue-filter.md, "Corroboration").
  // The accelerometer follows a block sticking to some member's base to this fraction of the
  // prediction (beside the noise and bias terms of the sliding test), [0.05, 0.7].
  Real follow_tolerance = Real(0.4);
  double follow_onset_s = 0.15;  // s: beyond it for every member's base this long, (0, 1]
  // rad/s: every member's own |theta'| beyond this (or collapsed) while the statue is measured
  // in full contact, for contradiction_s: a contradiction. [0.02, 0.5] rad/s, (0, 1] s.
  Real contradiction_rate_rad_s = Real(0.05);
  double contradiction_s = 0.1;
  // s: a refuted sensor is trusted again once every member and the statue stood in full contact
  // this long with the accelerometer following, [1, 600].
  double trust_again_s = 10.0;
};

// Why the ground sensors do not corroborate the statue sensor (StatueEstimate::refutation).
enum class StatueRefutation : std::uint8_t {
  kNone = 0,
  kNoAccelerometer,          // no fresh accelerometer sample for follow_onset_s
  kDoesNotFollowBase,        // its specific force is no block's sticking to a member's base
  kStillWhileMembersRock,    // measured in full contact while every member rocks or fell
  kUnexplained,              // no member explains the measured rotation
};
inline constexpr NameTable<StatueRefutation, 5> kStatueRefutationNames{{{
    {StatueRefutation::kNone, "none"},
    {StatueRefutation::kNoAccelerometer, "no_accelerometer"},
    {StatueRefutation::kDoesNotFollowBase, "does_not_follow_base"},
    {StatueRefutation::kStillWhileMembersRock, "still_while_every_member_rocks"},
    {StatueRefutation::kUnexplained, "unexplained"},
}}};
[[nodiscard]] constexpr const char* statue_refutation_name(StatueRefutation r) {
  return kStatueRefutationNames.name(r);
}

// Where the statue sensor's accelerometer sits on the block (StatueSensorSettings' mounting):
// its height above the block's base and its horizontal offset along the axis from the vertical
// through the block's centre of mass C, m.
struct StatueAccelerometerMount {
  Real height_m = 1.0;
  Real offset_m = 0.0;
};

// The specific force f = a - g_vec an accelerometer fixed on the block reads, in the block's
// frame (x along the axis, z up the block), m/s2: a point of the block at `reference`'s
// acceleration (horizontal, vertical; world frame, without gravity), the accelerometer at
// `from_reference` from it in the block's frame, the block turned by theta (> 0 about corner 1,
// counter-clockwise) at theta' and theta'':
//   r = R(theta) p,  a = a_ref + theta'' (-r_z, r_x) - theta'^2 r,  f = R(-theta) (a + (0, g)).
[[nodiscard]] Vector2r block_specific_force(const Vector2r& reference,
                                            const Vector2r& from_reference, Real theta,
                                            Real theta_dot, Real theta_ddot, Real g);

// What the accelerometer at `mount` reads on the simulated block (a Simulator's scene, mode,
// state and accelerations at the ground `ground`): C's acceleration from the contact's
// kinematics (Eqs 9-14), the rest by block_specific_force. Tests and plinth-eval simulate the
// statue sensor with it.
[[nodiscard]] Vector2r simulated_specific_force(const Scene& scene, const Mode& mode,
                                                const State& y, const Accelerations& acc,
                                                GroundAcceleration ground,
                                                const StatueAccelerometerMount& mount);

// Checks the settings; the Error names the field ("statue_filter.memory_s", ...).
[[nodiscard]] Error validate(const StatueFilterSettings& settings);

// One measured sample of an axis, in the statue frame.
struct StatueMeasurement {
  Real rotation_rate = 0.0;  // theta', rad/s (> 0 turns about corner 1)
  // The accelerometer's sample, fresh and healthy: its horizontal specific force along the
  // axis, m/s2 (statue frame, offset removed). Without one the phase is the gyroscope's alone.
  bool has_acceleration = false;
  Real specific_force_m_s2 = 0.0;
};

struct StatueEstimate {
  bool measuring = false;     // started and fed a sample since
  Mode mode;                  // the measured phase and corner (sliding: the accelerometer's)
  Real tilt = 0.0;            // theta, rad
  Real rotation_rate = 0.0;   // theta', rad/s
  Real effective_members = 0.0;  // 1 / sum w^2
  bool informative = false;
  bool explained = true;
  Real best_score = 0.0;      // the smallest member mean score
  Real span_score = 0.0;      // the mean score against the span of the members' predictions
  int best_member = 0;        // whose
  int intervals = 0;          // innovations taken since the start
  Risk risk;                  // the filter's risk (as above)
  int risk_member = 0;        // whose risk that is
  bool weighted = false;      // the risk is the weighted members' (informative and explained)
  int ruled_out = 0;          // members ruled out (explained only; 0 while unexplained)
  std::uint32_t ruled_out_members = 0;  // bit m: member m ruled out
  // bit m: member m's own theta' disagrees with the measured one now (not weighted only): its
  // own simulation's risk and forecast do not count.
  std::uint32_t disagreeing_members = 0;
  std::array<Real, kMaxEnsembleMembers> weights{};  // weights[0 .. members)
  // The accelerometer: its sample fed this one's sliding test (a scene that can slide).
  bool acceleration_used = false;
  // m/s2, filtered: f less the prediction sticking, by the member whose base explains the
  // reading best (the smallest ratio to its threshold), and that threshold.
  Real relative_acceleration = 0.0;
  Real slide_threshold = 0.0;
  // Corroborated: the sensor's reading may lower the risk below the box's without it. Else the
  // refutation that took that away (held until trust_again_s of rest; the latest one).
  bool corroborated = true;
  StatueRefutation refutation = StatueRefutation::kNone;
  bool follows_base = true;  // the newest accelerometer sample followed some member's base
};

// The forecast's probability of a collapse with the members weighted: the weight of the members
// that collapse within the horizon when the estimate is weighted; else, with members ruled out
// or disagreeing, the collapsing members among the others over their number; else (or none
// left) the forecast's own (collapsing / members).
[[nodiscard]] double weighted_collapse_probability(const ForecastOutcome& forecast,
                                                   const StatueEstimate& estimate);

class StatueFilter {
 public:
  // Refuses invalid settings and an interval shorter than one sample.
  [[nodiscard]] Error start(const StatueFilterSettings& settings, const EstimatorSettings& rate,
                            const RiskSettings& risk, int members,
                            const StatueAccelerometerMount& mount = {});
  // Forgets everything (the ensemble restarted): uniform weights, at rest.
  void reset();
  // The sample the ensemble's members just took (Ensemble::push(ground)) and the statue's
  // measured motion at the same time.
  void on_sample(const Ensemble& members, GroundAcceleration ground,
                 const StatueMeasurement& measured);

  [[nodiscard]] const StatueEstimate& estimate() const { return estimate_; }
  [[nodiscard]] const StatueFilterSettings& settings() const { return settings_; }

 private:
  void measure(const Ensemble& members, GroundAcceleration ground,
               const StatueMeasurement& measured);
  [[nodiscard]] bool accelerometer_reads_upright(const Ensemble& members,
                                                 GroundAcceleration ground,
                                                 const StatueMeasurement& measured,
                                                 Real tilt) const;
  [[nodiscard]] Real predicted_rate_change(const Ensemble& members, int m,
                                           GroundAcceleration ground) const;
  void finish_interval(const Ensemble& members);
  void weigh(const Ensemble& members);
  [[nodiscard]] State measured_state(const PlanarEstimator& member) const;
  // The accelerometer against a block sticking to each member's base: the filtered relative
  // accelerations; false without a usable accelerometer sample.
  bool compare_with_bases(const Ensemble& members, GroundAcceleration ground,
                          const StatueMeasurement& measured, const Real* previous_rate);
  void measure_sliding(const Ensemble& members, bool compared);
  [[nodiscard]] bool follows_some_base(const Ensemble& members, GroundAcceleration ground) const;
  void corroborate(const Ensemble& members, bool compared, GroundAcceleration ground);
  void stop_sliding();

  StatueFilterSettings settings_;
  RiskSettings risk_;
  Real period_ = 0.0;  // s, a sample period
  int members_ = 0;
  int interval_samples_ = 1;
  Real evidence_decay_ = 1.0;  // per interval
  Real score_decay_ = 1.0;
  int rest_samples_ = 1;

  StatueEstimate estimate_;
  Real previous_rate_ = 0.0;
  int still_samples_ = 0;
  // The interval in progress.
  int interval_count_ = 0;
  Real interval_start_rate_ = 0.0;
  Real interval_start_tilt_ = 0.0;
  bool interval_impact_ = false;  // an impact, a lift-off or a landing: the interval not scored
  bool interval_terminal_ = false;
  bool interval_moved_ = false;  // the measured statue left full contact in the interval
  std::array<Real, kMaxEnsembleMembers> previous_acceleration_{};  // theta'' rad/s2
  std::array<Real, kMaxEnsembleMembers> predicted_change_{};       // rad/s
  std::array<Real, kMaxEnsembleMembers> evidence_{};
  std::array<Real, kMaxEnsembleMembers> score_{};
  std::array<Real, kMaxEnsembleMembers> score_norm_{};
  // The same mean score of the measured change against the span of the members' predictions
  // (0 inside it): a statue between the members is explained by the ensemble, not by one.
  Real span_score_ = 0.0;
  Real span_score_norm_ = 0.0;
  bool have_previous_ = false;
  // The sliding test.
  Mode gyroscope_mode_;  // the phase the gyroscope alone measured last
  StatueAccelerometerMount mount_;
  Real slide_alpha_ = 1.0;            // the low-pass's weight of a new sample
  Real slide_noise_gain_ = 1.0;       // its output's noise over a white input's
  Real slide_rate_noise_gain_ = 0.0;  // 1/s2: a differenced rate's filtered noise over its own
  int slide_onset_samples_ = 1;
  int slide_end_samples_ = 1;
  int slide_above_ = 0;
  int slide_below_ = 0;
  bool sliding_ = false;
  // Per member (its base): a_rel and |f_predicted|, filtered, m/s2; the filtered noise.
  std::array<Real, kMaxEnsembleMembers> slide_relative_{};
  std::array<Real, kMaxEnsembleMembers> slide_scale_{};
  std::array<Real, kMaxEnsembleMembers> slide_noise_{};
  Real measured_force_ = 0.0;  // m/s2, f filtered alike (the sliding block's friction)
  bool compared_once_ = false;  // the filters hold a comparison since the last reset
  // Corroboration.
  int follow_onset_samples_ = 1;
  int contradiction_samples_ = 1;
  int trust_again_samples_ = 1;
  int beyond_samples_ = 0;          // consecutive samples no member's base explains
  int without_acceleration_ = 0;    // consecutive samples without an accelerometer sample
  int contradicting_samples_ = 0;   // consecutive samples of the contradiction
  int rest_agreeing_samples_ = 0;   // consecutive samples of rest, following (trust again)
};

}  // namespace plinth
