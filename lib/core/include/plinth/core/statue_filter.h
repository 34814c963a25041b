// The statue sensor's use: the members of an ensemble (ensemble.h) weighted by how well each
// explains the statue's measured rotation, the phase taken from the measurement, and the risk
// of the weighted members.
//
// The measurement is the rotation rate theta' of one axis (a gyroscope on the block, in the
// statue frame; its offset removed by the conditioning). The filter integrates it to the tilt
// theta (set back to 0 once the block has sat still: full contact is theta = 0), and takes the
// phase from the two: rocking about corner 1 or 2, full contact, overturned past every member's
// critical angle.
//
// Each member is judged on its equations at the *measured* state, not on its own simulated
// trajectory (which rocking's sensitivity to impacts soon separates from the statue's, right
// member or not): over every interval of interval_s, the member's theta'' of Eq 8 (rocking_flow;
// at rest, the rotation Eq 16's onset would start, or none) is integrated at the measured
// theta, theta' and ground, with the member's own base (u, u'), and the predicted change of
// theta' is compared with the measured one. An interval with an impact (the tilt changes sign)
// says nothing about the flow and is skipped. The innovation's variance is the gyroscope's noise
// at both ends plus the model's tolerance, a fraction of the larger change:
//   nu = d_meas - d_pred,  s^2 = 2 rate_noise^2 + (model_tolerance * max(|d_pred|, |d_meas|))^2
// and each member's evidence, a log likelihood with forgetting (memory_s), is
//   L <- L exp(-interval / memory_s) - nu^2 / (2 s^2) - ln s.
// The weights are exp(L - max L), normalised: a bank of fixed members with forgetting rather
// than a particle filter that resamples and jitters them (the members are the corners of the
// declared uncertainty, so the extremes are never lost; forgetting keeps the weights from
// collapsing onto one member for good, as resampling would).
//
// Informative: the effective number of members 1 / sum w^2 is at most informative_fraction of
// the members (uniform weights give all of them: nothing has been learned while the statue and
// every member sit still). The risk is then the highest member risk that members holding at
// least credible_weight of the weight reach (each member's overturning_risk at the measured
// phase and state). Before, the worst member's over the members not ruled out, of the measured
// state and of its own simulation, the latter only while the member's own theta' agrees with
// the measured one (within 3 standard deviations of the innovation: a member its base's stops
// just kicked into rocking while the statue stands is contradicted at once, before its next
// interval's evidence); the forecast's probability likewise counts the others. A member is
// ruled out once its weight is below ruled_out_fraction of the uniform 1 / members. Besides the
// flow's innovations, an interval through which the statue stood in full contact weighs
// against a member whose own simulation rocks (its theta' against the measured one): the
// evidence that the members' own trajectories give while they still follow the statue's.
//
// Explained: the smallest member's mean normalised innovation nu^2 / s^2 (forgetting over
// score_memory_s, over the intervals whose measured or predicted change is beyond 4 times the
// rate's noise; near 1 for the right member) stays below unexplained_score. Above it (an
// anchored, cracked or toppled statue, a loose sensor) no member explains the measurement: the
// filter says so and its risk is the worst member's, never less.
//
// Sliding, from the accelerometer (its horizontal specific force f along the axis, statue
// frame, offset removed). A block whose contact with its base sticks moves with the base: the
// accelerometer reads what a point of a rigid body pivoting on the base reads, the base's
// absolute acceleration a_b = u'' + u_G'' (the ground's on the ground; on an isolated base each
// member's own, Ensemble::base_acceleration) plus the tilt's terms: the gravity's projection
// g sin(theta) and, while it rocks, the lever arm's theta'' and centripetal theta'^2 terms about
// the pivot (block_specific_force; theta and theta' from the gyroscope, theta'' their difference
// over a sample, the same low-pass as the rest). A sliding block's acceleration is its
// friction's, -mu_k sign(x') (g + v_G'') (Eqs 4-5), not the base's: the relative acceleration
//   a_rel = f - f_predicted   (= x'' while it slides, 0 while it sticks)
// stays away from 0. Low-passed over slide_filter_s, it is compared with
//   4 sigma_f + acceleration_bias_m_s2 + slide_tolerance * |f_predicted|
// (sigma_f the filtered noise of the accelerometers' and, rocking, of the differenced rate at
// the lever arm; the tolerance the model's and the two sensors' timing), for every member's base
// (the members span the declared uncertainty of an isolated base; on the ground they share it):
// above for every member for slide_onset_s the block slides (slide-rocking while the gyroscope
// says it rocks), within it for some member for slide_end_s it sticks again. An impact's jump of
// the sensor's velocity is in the differenced rate too (theta'' h at theta = 0 about either
// corner): the prediction carries it. The sliding direction is the opposite of the block's
// acceleration's. Only for a scene that can slide ([friction]) and, by default, stands on the
// ground: on an isolated base the members' simulated bases are not the statue's (no sensor
// measures the plate), which gave sliding before the statue moved in 36 of 217 runs
// (docs/forecast.md); slide_on_isolated_base turns it on there. Without a fresh accelerometer
// sample the phase is the gyroscope's alone.
// Freestanding: no heap.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/ensemble.h"
#include "plinth/core/error.h"
#include "plinth/core/excitation.h"
#include "plinth/core/forecast.h"
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

struct StatueFilterSettings {
  Real rate_noise_rad_s = Real(0.003);  // rad/s: one measured rate's noise (gyro noise, bias left)
  Real model_tolerance = Real(0.25);   // the members' theta'' holds to this fraction, (0, 2]
  Real rest_rate_rad_s = Real(0.02);   // rad/s: |theta'| below this (and the tilt below
  Real rest_tilt_rad = Real(0.002);    // rad: this) is at rest
  double rest_time_s = 0.1;            // s: at rest this long with a small tilt sets theta to 0
  double interval_s = 0.05;            // s: the innovations' interval, [1 sample, 1 s]
  double memory_s = 10.0;              // s: the evidence's forgetting time constant
  double score_memory_s = 1.0;         // s: the innovations' mean score's time constant
  Real informative_fraction = Real(0.5);  // informative: effective members <= this * members
  Real credible_weight = Real(0.2);       // the risk: reached by members holding this weight
  Real unexplained_score = Real(6);       // mean nu^2 / s^2 of the best member above: unexplained
  Real ruled_out_fraction = Real(0.1);    // weight below this x 1 / members: ruled out, (0, 1]
  // Sliding from the accelerometer (above).
  Real acceleration_noise_m_s2 = Real(0.03);  // m/s2 rms: a sample of f less the ground's, noise
  Real acceleration_bias_m_s2 = Real(0.15);   // m/s2: their biases left after the offsets, >= 0
  Real slide_tolerance = Real(0.15);  // the prediction holds to this fraction of itself, [0, 1)
  double slide_filter_s = 0.05;       // s: the relative acceleration's low-pass, (0, 1]
  double slide_onset_s = 0.05;        // s: above the threshold this long: sliding, (0, 1]
  double slide_end_s = 0.15;          // s: below it this long: stuck again, (0, 1]
  bool slide_on_isolated_base = false;  // the test on an isolated base too (above)
};

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
  void measure(const Ensemble& members, const StatueMeasurement& measured);
  [[nodiscard]] Real predicted_rate_change(const Ensemble& members, int m,
                                           GroundAcceleration ground) const;
  void finish_interval(const Ensemble& members);
  void weigh(const Ensemble& members);
  [[nodiscard]] State measured_state(const PlanarEstimator& member) const;
  void measure_sliding(const Ensemble& members, GroundAcceleration ground,
                       const StatueMeasurement& measured, const Real* previous_rate);
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
  bool interval_impact_ = false;
  bool interval_terminal_ = false;
  bool interval_moved_ = false;  // the measured statue left full contact in the interval
  std::array<Real, kMaxEnsembleMembers> previous_acceleration_{};  // theta'' rad/s2
  std::array<Real, kMaxEnsembleMembers> predicted_change_{};       // rad/s
  std::array<Real, kMaxEnsembleMembers> evidence_{};
  std::array<Real, kMaxEnsembleMembers> score_{};
  std::array<Real, kMaxEnsembleMembers> score_norm_{};
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
  // Per member (its base): a_rel and |f_predicted|, filtered, m/s2.
  std::array<Real, kMaxEnsembleMembers> slide_relative_{};
  std::array<Real, kMaxEnsembleMembers> slide_scale_{};
};

}  // namespace plinth
