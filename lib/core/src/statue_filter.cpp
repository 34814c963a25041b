#include "plinth/core/statue_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "build_options.h"
#include "plinth/core/internal/flows.h"

namespace plinth {

namespace {

// The mean score judges the model once it holds this many scored intervals (their decayed
// count): one interval is no statistic. A rate's noise alone passes the signal gate about once
// in 200 quiet intervals, and that one interval, selected for being large, scores 3 to 8; a
// correct model's mean of 3 intervals passes unexplained_score (6) with probability 5e-4.
constexpr Real kMinScoredIntervals = 3;
// A change of theta' over an interval is a signal beyond this many times one rate's noise.
constexpr Real kSignal = 4;
// A member's own theta' agrees with the measured one within this many standard deviations
// (the innovation's: noise and model tolerance).
constexpr Real kAgreement = 3;
// The sliding test's threshold: this many standard deviations of the filtered noise.
constexpr Real kSlideSigmas = 4;
// A build whose feature sets all leave sliding out (PLINTH_CORE_FEATURE_SETS: a microcontroller's,
// which refuses every scene with [friction]) leaves the sliding test out: the sets with sliding
// are the contacts 1-3 of each base, bits 1-3, 5-7 and 9-11 (feature_sets.cpp).
constexpr bool kSlidingBuiltIn = (PLINTH_CORE_FEATURE_MASK & 0xEEE) != 0;

// theta'' of `scene` at the measured mode and state (Eq 8); at rest the rotation that Eq 16's
// onset starts about either corner (the flow at theta = theta' = 0 turning away from the
// ground), else none.
Real rotational_acceleration(const Scene& scene, const Mode& measured, const State& y,
                             bool base_moves, GroundAcceleration ground) {
  if (measured.rocking()) {
    return internal::rocking_flow(scene, scene.corner(measured.corner), y, ground, base_moves)
        .theta;
  }
  if (measured.terminal()) return 0;
  State at_rest = y;
  at_rest[kTheta] = 0;
  at_rest[kThetaDot] = 0;
  const Real left =
      internal::rocking_flow(scene, scene.corner1, at_rest, ground, base_moves).theta;
  if (left > 0) return left;
  const Real right =
      internal::rocking_flow(scene, scene.corner2, at_rest, ground, base_moves).theta;
  return right < 0 ? right : Real(0);
}

}  // namespace

// A tunable within [low, high] (low excluded when `open_low`), its reason naming the range.
static Error check_range(double value, double low, double high, bool open_low, const char* field,
                  const char* reason) {
  if (!std::isfinite(value)) return {ErrorCode::kNotFinite, field, "must be finite"};
  if (value < low || (open_low && value <= low)) {
    return {ErrorCode::kOutOfRange, field, reason, low};
  }
  if (value > high) return {ErrorCode::kOutOfRange, field, reason, high};
  return ok_error();
}

// The bounds are physical where the quantity is (a gyroscope's noise, a rest rate, a tilt), and
// elsewhere where a value stops meaning what its name says and starts switching a check off
// (docs/statue-filter.md, "Bounds").
Error validate(const StatueFilterSettings& s) {
  const struct {
    double value;
    double low;
    double high;
    bool open_low;
    const char* field;
    const char* reason;
  } kRanges[] = {
      {s.rate_noise_rad_s, 1e-4, 0.05, false, "statue_filter.rate_noise_rad_s",
       "must lie in [1e-4, 0.05] rad/s"},
      {s.model_tolerance, 0.05, 1.0, false, "statue_filter.model_tolerance",
       "must lie in [0.05, 1]"},
      {s.rest_rate_rad_s, 0.0, 0.05, true, "statue_filter.rest_rate_rad_s",
       "must lie in (0, 0.05] rad/s"},
      {s.rest_tilt_rad, 0.0, 0.01, true, "statue_filter.rest_tilt_rad",
       "must lie in (0, 0.01] rad"},
      {s.rest_time_s, 0.0, 10.0, true, "statue_filter.rest_time_s", "must lie in (0, 10] s"},
      {s.interval_s, 0.0, 1.0, true, "statue_filter.interval_s", "must lie in (0, 1] s"},
      {s.memory_s, 1.0, 600.0, false, "statue_filter.memory_s", "must lie in [1, 600] s"},
      {s.score_memory_s, 0.1, 60.0, false, "statue_filter.score_memory_s",
       "must lie in [0.1, 60] s"},
      {s.informative_fraction, 0.0, 1.0, true, "statue_filter.informative_fraction",
       "must lie in (0, 1]"},
      {s.credible_weight, 0.0, 0.5, true, "statue_filter.credible_weight",
       "must lie in (0, 0.5]"},
      {s.unexplained_score, 2.0, 50.0, false, "statue_filter.unexplained_score",
       "must lie in [2, 50]"},
      {s.ruled_out_fraction, 0.0, 0.5, true, "statue_filter.ruled_out_fraction",
       "must lie in (0, 0.5]"},
      {s.acceleration_noise_m_s2, 0.0, 1.0, true, "statue_filter.acceleration_noise_m_s2",
       "must lie in (0, 1] m/s2"},
      {s.acceleration_bias_m_s2, 0.0, 1.0, false, "statue_filter.acceleration_bias_m_s2",
       "must lie in [0, 1] m/s2"},
      {s.slide_tolerance, 0.0, 0.5, false, "statue_filter.slide_tolerance",
       "must lie in [0, 0.5]"},
      {s.slide_filter_s, 0.0, 1.0, true, "statue_filter.slide_filter_s", "must lie in (0, 1] s"},
      {s.slide_onset_s, 0.0, 1.0, true, "statue_filter.slide_onset_s", "must lie in (0, 1] s"},
      {s.slide_end_s, 0.0, 1.0, true, "statue_filter.slide_end_s", "must lie in (0, 1] s"},
      {s.follow_tolerance, 0.05, 0.7, false, "statue_filter.follow_tolerance",
       "must lie in [0.05, 0.7]"},
      {s.follow_onset_s, 0.0, 1.0, true, "statue_filter.follow_onset_s",
       "must lie in (0, 1] s"},
      {s.contradiction_rate_rad_s, 0.02, 0.5, false, "statue_filter.contradiction_rate_rad_s",
       "must lie in [0.02, 0.5] rad/s"},
      {s.contradiction_s, 0.0, 1.0, true, "statue_filter.contradiction_s",
       "must lie in (0, 1] s"},
      {s.trust_again_s, 1.0, 600.0, false, "statue_filter.trust_again_s",
       "must lie in [1, 600] s"},
  };
  for (const auto& r : kRanges) {
    PLINTH_TRY(check_range(r.value, r.low, r.high, r.open_low, r.field, r.reason));
  }
  return ok_error();
}

Vector2r block_specific_force(const Vector2r& reference, const Vector2r& from_reference,
                              Real theta, Real theta_dot, Real theta_ddot, Real g) {
  const internal::SinCos t = internal::sin_cos(theta);
  const Vector2r r(t.cos * from_reference.x() - t.sin * from_reference.y(),
                   t.sin * from_reference.x() + t.cos * from_reference.y());
  const Vector2r world = reference + theta_ddot * Vector2r(-r.y(), r.x()) -
                         theta_dot * theta_dot * r + Vector2r(Real(0), g);
  return {t.cos * world.x() + t.sin * world.y(), -t.sin * world.x() + t.cos * world.y()};
}

Vector2r simulated_specific_force(const Scene& scene, const Mode& mode, const State& y,
                                  const Accelerations& acc, GroundAcceleration ground,
                                  const StatueAccelerometerMount& mount) {
  // C's acceleration (as base_stop_reaction takes it), the ground's added.
  const internal::PivotDistance pivot =
      internal::pivot_distance(scene, mode.corner, mode.overhang, y[kX]);
  const internal::ContactKinematics k = internal::contact_kinematics(
      scene, pivot.offset(), pivot.overhanging, y, internal::sin_cos(y[kTheta]));
  const Vector3r qdd(acc.u, acc.x, acc.theta);
  const Vector2r c(k.jx.dot(qdd) + k.bias.x() + ground.horizontal,
                   k.jy.dot(qdd) + k.bias.y() + ground.vertical);
  return block_specific_force(c, Vector2r(mount.offset_m, mount.height_m - scene.h), y[kTheta],
                              y[kThetaDot], acc.theta, scene.g);
}

double weighted_collapse_probability(const ForecastOutcome& forecast,
                                     const StatueEstimate& estimate) {
  const std::uint32_t left_out = estimate.ruled_out_members | estimate.disagreeing_members;
  if (!forecast.valid || (!estimate.weighted && left_out == 0)) return forecast.probability;
  Real p = 0;
  int counted = 0;
  for (int m = 0; m < forecast.members && m < kMaxEnsembleMembers; ++m) {
    const auto bit = static_cast<unsigned>(m);
    const bool collapses = (forecast.collapsing_members >> bit & 1U) != 0U;
    if (estimate.weighted) {
      p += collapses ? estimate.weights[static_cast<std::size_t>(m)] : Real(0);
    } else if ((left_out >> bit & 1U) == 0U) {
      ++counted;
      p += collapses ? Real(1) : Real(0);
    }
  }
  // Weights that sum to 1 can sum past it by a rounding when every member collapses, and the
  // alarm policy takes a probability above 1 for an internal fault: the box showed `fault` in
  // place of `alarm` until the forecast changed (docs/forecast.md, "The alarm a rounding held").
  if (estimate.weighted) return static_cast<double>(std::min(p, Real(1)));
  return counted > 0 ? static_cast<double>(p) / counted : forecast.probability;
}

Error StatueFilter::start(const StatueFilterSettings& settings, const EstimatorSettings& rate,
                          const RiskSettings& risk, int members,
                          const StatueAccelerometerMount& mount) {
  PLINTH_TRY(validate(settings));
  PLINTH_TRY(validate(risk));
  if (members < 1 || members > kMaxEnsembleMembers) {
    return {ErrorCode::kOutOfRange, "uncertainty",
            "gives more ensemble members than this build holds (kMaxEnsembleMembers)",
            static_cast<double>(kMaxEnsembleMembers)};
  }
  const double period = rate.sample_period();
  if (settings.interval_s < period) {
    return {ErrorCode::kOutOfRange, "statue_filter.interval_s",
            "is shorter than one sample period", period};
  }
  settings_ = settings;
  risk_ = risk;
  period_ = static_cast<Real>(period);
  members_ = members;
  interval_samples_ = static_cast<int>(std::lround(settings.interval_s / period));
  const double interval = interval_samples_ * period;
  evidence_decay_ = static_cast<Real>(std::exp(-interval / settings.memory_s));
  score_decay_ = static_cast<Real>(std::exp(-interval / settings.score_memory_s));
  rest_samples_ = static_cast<int>(std::ceil(settings.rest_time_s / period));
  mount_ = mount;
  // The first-order low-pass y += alpha (x - y): a white input's variance times
  // alpha / (2 - alpha); a differenced one's ((x_n - x_{n-1}) / T) times
  // 2 alpha^2 / (T^2 (2 - alpha)).
  // (In Real: a float build's sqrt is an instruction, libm's double one 0.5 KB of flash.)
  const auto alpha = static_cast<Real>(1.0 - std::exp(-period / settings.slide_filter_s));
  slide_alpha_ = alpha;
  slide_noise_gain_ = std::sqrt(alpha / (Real(2) - alpha));
  slide_rate_noise_gain_ = alpha / period_ * std::sqrt(Real(2) / (Real(2) - alpha));
  const auto samples = [period](double s) {
    return std::max(1, static_cast<int>(std::lround(s / period)));
  };
  slide_onset_samples_ = samples(settings.slide_onset_s);
  slide_end_samples_ = samples(settings.slide_end_s);
  follow_onset_samples_ = samples(settings.follow_onset_s);
  contradiction_samples_ = samples(settings.contradiction_s);
  trust_again_samples_ = samples(settings.trust_again_s);
  reset();
  return ok_error();
}

void StatueFilter::reset() {
  estimate_ = StatueEstimate{};
  const Real uniform = Real(1) / static_cast<Real>(members_);
  for (int m = 0; m < members_; ++m) estimate_.weights[static_cast<std::size_t>(m)] = uniform;
  estimate_.effective_members = static_cast<Real>(members_);
  previous_rate_ = 0;
  still_samples_ = 0;
  interval_count_ = 0;
  interval_start_rate_ = 0;
  interval_start_tilt_ = 0;
  interval_impact_ = false;
  interval_terminal_ = false;
  interval_moved_ = false;
  previous_acceleration_.fill(0);
  predicted_change_.fill(0);
  evidence_.fill(0);
  score_.fill(0);
  score_norm_.fill(0);
  span_score_ = 0;
  span_score_norm_ = 0;
  have_previous_ = false;
  gyroscope_mode_ = Mode{};
  stop_sliding();
  slide_relative_.fill(0);
  slide_scale_.fill(0);
  slide_noise_.fill(0);
  measured_force_ = 0;
  compared_once_ = false;
  beyond_samples_ = 0;
  without_acceleration_ = 0;
  contradicting_samples_ = 0;
  rest_agreeing_samples_ = 0;
}

// The sliding test forgets (no fresh accelerometer sample, or a restart): stuck, as the
// gyroscope alone would say.
void StatueFilter::stop_sliding() {
  slide_above_ = 0;
  slide_below_ = 0;
  sliding_ = false;
  estimate_.acceleration_used = false;
  estimate_.relative_acceleration = 0;
  estimate_.slide_threshold = 0;
}

// The accelerometer's specific force against what it reads on a block sticking to each
// member's base (the pivot moving as the member's own simulation moves its base; the block's
// rotation from the gyroscope): the relative acceleration a_rel = f - f_predicted, |f_predicted|
// and the noise, low-passed over slide_filter_s from 0. `previous_rate` the rate before this
// sample's, if any. False (nothing compared, the filters forgotten) without a usable sample or
// once the gyroscope says collapse.
bool StatueFilter::compare_with_bases(const Ensemble& members, GroundAcceleration ground,
                                      const StatueMeasurement& measured,
                                      const Real* previous_rate) {
  const Mode& gyroscope = gyroscope_mode_;  // on_sample() set it to measure()'s phase
  if (!measured.has_acceleration || !std::isfinite(measured.specific_force_m_s2) ||
      gyroscope.terminal()) {
    if (compared_once_) {  // the filters forget: they start from 0 on the next sample
      slide_relative_.fill(0);
      slide_scale_.fill(0);
      measured_force_ = 0;
      compared_once_ = false;
    }
    return false;
  }
  compared_once_ = true;
  const bool rocking = gyroscope.rocking();
  const Real theta_ddot =
      previous_rate != nullptr ? (estimate_.rotation_rate - *previous_rate) / period_ : Real(0);
  const Real acceleration_noise = settings_.acceleration_noise_m_s2 * slide_noise_gain_;
  const Real alpha = slide_alpha_;
  measured_force_ += alpha * (measured.specific_force_m_s2 - measured_force_);
  for (int m = 0; m < members_; ++m) {
    const auto k = static_cast<std::size_t>(m);
    const Scene& scene = members.member(m).scene();
    const Real base = members.base_acceleration(m);
    const Vector2r from_pivot(scene.corner(gyroscope.corner).offset + mount_.offset_m,
                              mount_.height_m);
    const Real predicted =
        block_specific_force(Vector2r(base, ground.vertical), from_pivot, estimate_.tilt,
                             rocking ? estimate_.rotation_rate : Real(0),
                             rocking ? theta_ddot : Real(0), scene.g)
            .x();
    slide_relative_[k] += alpha * (measured.specific_force_m_s2 - predicted - slide_relative_[k]);
    slide_scale_[k] += alpha * (std::fabs(predicted) - slide_scale_[k]);
    // The filtered noise: the accelerometers', and rocking the differenced rate's at the lever.
    const Real rate_noise = rocking ? settings_.rate_noise_rad_s * from_pivot.norm() *
                                          slide_rate_noise_gain_
                                    : Real(0);
    slide_noise_[k] =
        std::sqrt(acceleration_noise * acceleration_noise + rate_noise * rate_noise);
  }
  return true;
}

// Sliding (a scene that can slide; on an isolated base only with slide_on_isolated_base):
// once no member's base, sticking, explains the reading, debounced both ways. Needs this
// sample's comparison (compare_with_bases).
void StatueFilter::measure_sliding(const Ensemble& members, bool compared) {
  const SceneParams& nominal = members.nominal().scene().params;
  if (!kSlidingBuiltIn || !nominal.has_friction ||
      (nominal.has_base && !settings_.slide_on_isolated_base) || !compared) {
    if (estimate_.acceleration_used) stop_sliding();  // else nothing to forget
    return;
  }
  estimate_.acceleration_used = true;
  bool explained = false;  // some member's base, sticking, explains the reading
  Real closest = -1;       // the smallest |a_rel| / threshold, and its member's
  Real closest_block = 0;  // the block's acceleration by that member's base
  for (int m = 0; m < members_; ++m) {
    const auto k = static_cast<std::size_t>(m);
    const Real relative = slide_relative_[k];
    const Real threshold = kSlideSigmas * slide_noise_[k] + settings_.acceleration_bias_m_s2 +
                           settings_.slide_tolerance * slide_scale_[k];
    const Real ratio = std::fabs(relative) / threshold;
    if (closest < 0 || ratio < closest) {
      closest = ratio;
      closest_block = members.base_acceleration(m) + relative;
      estimate_.relative_acceleration = relative;
      estimate_.slide_threshold = threshold;
    }
    explained = explained || ratio <= 1;
  }
  // Debounced both ways.
  if (!explained) {
    ++slide_above_;
    slide_below_ = 0;
  } else {
    ++slide_below_;
    slide_above_ = 0;
  }
  if (!sliding_ && slide_above_ >= slide_onset_samples_) sliding_ = true;
  if (sliding_ && slide_below_ >= slide_end_samples_) sliding_ = false;
  if (!sliding_) return;
  estimate_.mode.phase = gyroscope_mode_.rocking() ? Phase::kSlideRocking : Phase::kSliding;
  // Kinetic friction opposes the slip: the block's acceleration has the sign of -x'.
  estimate_.mode.slide_direction = closest_block > 0 ? std::int8_t{-1} : std::int8_t{1};
}

// Does the accelerometer read what a block on one of the members' bases reads: sticking to it
// (within follow_tolerance of the prediction, beside the sliding test's noise and bias terms),
// or, for a member that can slide, sliding on it (|f| the friction's, mu (g + v_G''), Eqs 4-5,
// between its kinetic and static coefficients, alike)? A frozen, loose, turned or misread sensor
// does not, once the base moves beyond those terms.
bool StatueFilter::follows_some_base(const Ensemble& members, GroundAcceleration ground) const {
  for (int m = 0; m < members_; ++m) {
    const auto k = static_cast<std::size_t>(m);
    const Real floor = kSlideSigmas * slide_noise_[k] + settings_.acceleration_bias_m_s2;
    if (std::fabs(slide_relative_[k]) <= floor + settings_.follow_tolerance * slide_scale_[k]) {
      return true;
    }
    const SceneParams& p = members.member(m).scene().params;
    if (!kSlidingBuiltIn || !p.has_friction) continue;
    const Real normal = members.member(m).scene().g + ground.vertical;  // per unit mass
    const Real low = p.friction.kinetic_coefficient * normal * (1 - settings_.follow_tolerance);
    const Real high = p.friction.static_coefficient * normal * (1 + settings_.follow_tolerance);
    const Real f = std::fabs(measured_force_);
    if (f >= low - floor && f <= high + floor) return true;
  }
  return false;
}

// Corroboration (docs/statue-filter.md): refuted by the first that holds: no accelerometer
// sample for follow_onset_s; the accelerometer following no member's base for follow_onset_s;
// the statue measured in full contact while every member's own simulation rocks (|theta'| beyond
// contradiction_rate_rad_s) or collapsed, for contradiction_s; no member explaining the
// rotation. A refutation holds until every member and the statue stood in full contact, the
// accelerometer following, for trust_again_s.
void StatueFilter::corroborate(const Ensemble& members, bool compared, GroundAcceleration ground) {
  if (compared) {
    without_acceleration_ = 0;
    estimate_.follows_base = follows_some_base(members, ground);
    beyond_samples_ = estimate_.follows_base ? 0 : beyond_samples_ + 1;
  } else if (!gyroscope_mode_.terminal()) {
    ++without_acceleration_;
  }
  bool every_member_rocks = gyroscope_mode_.phase == Phase::kFullContact;
  bool every_member_stands = true;
  for (int m = 0; m < members_; ++m) {
    const PlanarEstimator& e = members.member(m);
    const Mode& own = e.mode();
    const bool rocks = own.terminal() || (own.rocking() && std::fabs(e.state()[kThetaDot]) >
                                                                settings_.contradiction_rate_rad_s);
    every_member_rocks = every_member_rocks && rocks;
    every_member_stands = every_member_stands && own.phase == Phase::kFullContact;
  }
  contradicting_samples_ = every_member_rocks ? contradicting_samples_ + 1 : 0;
  StatueRefutation now = StatueRefutation::kNone;
  if (without_acceleration_ >= follow_onset_samples_) {
    now = StatueRefutation::kNoAccelerometer;
  } else if (beyond_samples_ >= follow_onset_samples_) {
    now = StatueRefutation::kDoesNotFollowBase;
  } else if (contradicting_samples_ >= contradiction_samples_) {
    now = StatueRefutation::kStillWhileMembersRock;
  } else if (!estimate_.explained) {
    now = StatueRefutation::kUnexplained;
  }
  if (now != StatueRefutation::kNone) {
    estimate_.corroborated = false;
    estimate_.refutation = now;
    rest_agreeing_samples_ = 0;
    return;
  }
  if (estimate_.corroborated) return;
  const bool at_rest = every_member_stands && gyroscope_mode_.phase == Phase::kFullContact &&
                       compared && estimate_.follows_base;
  rest_agreeing_samples_ = at_rest ? rest_agreeing_samples_ + 1 : 0;
  if (rest_agreeing_samples_ >= trust_again_samples_) {
    estimate_.corroborated = true;
    estimate_.refutation = StatueRefutation::kNone;
  }
}

// The measured state as member `member` would have it: its own base and sliding (not measured),
// the measured rotation.
State StatueFilter::measured_state(const PlanarEstimator& member) const {
  State y = member.state();
  y[kTheta] = estimate_.tilt;
  y[kThetaDot] = estimate_.rotation_rate;
  return y;
}

// Whether the accelerometer's sample (a block held still: theta' and theta'' 0) reads the block
// upright on some member's base at least as well as tilted by `tilt`; true where it cannot tell
// the two apart (g sin(tilt) within its noise and bias) or has no sample. A rocking block held
// at a swing's end by the ground's push is still too, but leaning: its gravity shows.
bool StatueFilter::accelerometer_reads_upright(const Ensemble& members, GroundAcceleration ground,
                                               const StatueMeasurement& measured,
                                               Real tilt) const {
  if (!measured.has_acceleration || !std::isfinite(measured.specific_force_m_s2)) return true;
  const Real g = members.nominal().scene().g;
  const Real floor =
      kSlideSigmas * settings_.acceleration_noise_m_s2 + settings_.acceleration_bias_m_s2;
  if ((g + ground.vertical) * std::fabs(std::sin(tilt)) <= floor) return true;
  Real upright = std::numeric_limits<Real>::infinity();
  Real leaning = std::numeric_limits<Real>::infinity();
  const Vector2r at_rest = Vector2r::Zero();  // theta' = theta'' = 0: the lever plays no part
  const Real f = measured.specific_force_m_s2;
  for (int m = 0; m < members_; ++m) {
    const Vector2r base(members.base_acceleration(m), ground.vertical);
    const Real reads_upright = block_specific_force(base, at_rest, 0, 0, 0, g).x();
    const Real reads_leaning = block_specific_force(base, at_rest, tilt, 0, 0, g).x();
    upright = std::fmin(upright, std::fabs(f - reads_upright));
    leaning = std::fmin(leaning, std::fabs(f - reads_leaning));
  }
  return upright <= leaning;
}

// The tilt (the rate integrated by the trapezoid rule, back to 0 once still and nearly upright)
// and the phase.
void StatueFilter::measure(const Ensemble& members, GroundAcceleration ground,
                           const StatueMeasurement& measured) {
  const Real rate = measured.rotation_rate;
  Real tilt = estimate_.tilt;
  if (have_previous_) tilt += Real(0.5) * (previous_rate_ + rate) * period_;
  Real largest_critical = 0;
  Real smallest_critical = Real(10);
  for (int m = 0; m < members_; ++m) {
    const Scene& s = members.member(m).scene();
    const Real a = std::fmin(s.corner1.critical_angle, s.corner2.critical_angle);
    const Real b = std::fmax(s.corner1.critical_angle, s.corner2.critical_angle);
    largest_critical = std::fmax(largest_critical, b);
    smallest_critical = std::fmin(smallest_critical, a);
  }
  still_samples_ = std::fabs(rate) < settings_.rest_rate_rad_s ? still_samples_ + 1 : 0;
  // Full contact is theta = 0: a block that sat still well inside its smallest critical angle is
  // back on its base (what the integrated rate says otherwise is the gyroscope's drift), unless
  // its accelerometer reads it leaning (held at a swing's end: taken for rest, the tilt lost put
  // every later prediction on the wrong corner, a false statue_unexplained).
  if (still_samples_ >= rest_samples_ && std::fabs(tilt) < Real(0.5) * smallest_critical &&
      accelerometer_reads_upright(members, ground, measured, tilt)) {
    tilt = 0;
  }
  if ((tilt > 0) != (estimate_.tilt > 0) && estimate_.tilt != 0 && tilt != 0) {
    interval_impact_ = true;  // the tilt changed sign: an impact
  }
  Mode mode;
  const bool moving = std::fabs(tilt) > settings_.rest_tilt_rad ||
                      std::fabs(rate) > settings_.rest_rate_rad_s;
  if (std::fabs(tilt) >= largest_critical) {
    mode.phase = Phase::kOverturned;
  } else if (moving) {
    mode.phase = Phase::kRocking;
  }
  const Real side = std::fabs(tilt) > settings_.rest_tilt_rad ? tilt : rate;
  mode.corner = side >= 0 ? Corner::kLeft : Corner::kRight;
  if (mode.rocking() && gyroscope_mode_.rocking() && mode.corner != gyroscope_mode_.corner) {
    interval_impact_ = true;
  }
  // Lifting off or landing within the interval: its predictions are of one phase, the measured
  // change spans two (at lift-off the tilt's sign, within its noise, may name the wrong corner).
  if ((mode.phase == Phase::kFullContact) != (gyroscope_mode_.phase == Phase::kFullContact)) {
    interval_impact_ = true;
  }
  if (mode.terminal()) interval_terminal_ = true;
  if (mode.phase != Phase::kFullContact) interval_moved_ = true;  // rocked (the gyroscope's)
  estimate_.mode = mode;
  estimate_.tilt = tilt;
  estimate_.rotation_rate = rate;
  previous_rate_ = rate;
}

void StatueFilter::on_sample(const Ensemble& members, GroundAcceleration ground,
                             const StatueMeasurement& measured) {
  if (members_ == 0 || members.size() != members_) return;
  if (!std::isfinite(measured.rotation_rate)) return;  // the conditioning passes none
  const Real previous_rate = previous_rate_;
  const bool had_previous = have_previous_;
  measure(members, ground, measured);
  gyroscope_mode_ = estimate_.mode;
  const bool compared =
      compare_with_bases(members, ground, measured, had_previous ? &previous_rate : nullptr);
  measure_sliding(members, compared);
  if (!have_previous_ || interval_count_ == 0) {
    interval_start_rate_ = estimate_.rotation_rate;
    interval_start_tilt_ = estimate_.tilt;
  }
  for (int m = 0; m < members_; ++m) {
    const PlanarEstimator& e = members.member(m);
    const bool base_moves = e.scene().has_base() && e.mode().held_stop == 0;
    const Real a = rotational_acceleration(e.scene(), gyroscope_mode_, measured_state(e),
                                           base_moves, ground);
    const auto k = static_cast<std::size_t>(m);
    if (have_previous_ && interval_count_ > 0) {
      predicted_change_[k] += Real(0.5) * (previous_acceleration_[k] + a) * period_;
    }
    previous_acceleration_[k] = a;
  }
  have_previous_ = true;
  estimate_.measuring = true;
  if (++interval_count_ > interval_samples_) finish_interval(members);
  weigh(members);
  corroborate(members, compared, ground);
}

void StatueFilter::finish_interval(const Ensemble& members) {
  const Real measured_change = estimate_.rotation_rate - interval_start_rate_;
  if (!interval_impact_ && !interval_terminal_) {
    const Real noise2 = Real(2) * settings_.rate_noise_rad_s * settings_.rate_noise_rad_s;
    const Real signal_scale = settings_.model_tolerance * kSignal * settings_.rate_noise_rad_s;
    Real lowest = predicted_change_[0];
    Real highest = predicted_change_[0];
    for (int m = 0; m < members_; ++m) {
      const auto k = static_cast<std::size_t>(m);
      lowest = std::fmin(lowest, predicted_change_[k]);
      highest = std::fmax(highest, predicted_change_[k]);
      const Real predicted = predicted_change_[k];
      const Real nu = measured_change - predicted;
      const Real scale =
          settings_.model_tolerance * std::fmax(std::fabs(predicted), std::fabs(measured_change));
      const Real s2 = noise2 + scale * scale;
      const Real chi2 = nu * nu / s2;
      evidence_[k] = evidence_[k] * evidence_decay_ - Real(0.5) * chi2 - Real(0.5) * std::log(s2);
      // The score counts intervals with a change beyond the noise, measured or predicted: an
      // interval where nothing moves and nothing should says nothing about the model.
      if (scale > signal_scale) {
        score_[k] = score_[k] * score_decay_ + chi2;
        score_norm_[k] = score_norm_[k] * score_decay_ + 1;
      }
    }
    // The members span the declared uncertainty, so a true statue inside it changes its rate
    // between theirs: beyond that span, by the same tolerance, it is unexplained.
    const Real outside = std::fmax(Real(0), std::fmax(lowest - measured_change,
                                                      measured_change - highest));
    const Real span_scale = settings_.model_tolerance *
                            std::fmax(std::fmax(std::fabs(lowest), std::fabs(highest)),
                                      std::fabs(measured_change));
    if (span_scale > signal_scale) {
      span_score_ =
          span_score_ * score_decay_ + outside * outside / (noise2 + span_scale * span_scale);
      span_score_norm_ = span_score_norm_ * score_decay_ + 1;
    }
    ++estimate_.intervals;
  }
  // The statue stood throughout: a member whose own simulation rocks is contradicted by its
  // rate (its theta' against the measured one, the flow's innovation at the interval's end).
  if (!interval_moved_ && !interval_terminal_) {
    const Real noise2 = Real(2) * settings_.rate_noise_rad_s * settings_.rate_noise_rad_s;
    for (int m = 0; m < members_; ++m) {
      const PlanarEstimator& e = members.member(m);
      if (e.mode().phase == Phase::kFullContact) continue;
      const Real own = e.state()[kThetaDot];
      const Real nu = own - estimate_.rotation_rate;
      const Real scale = settings_.model_tolerance * std::fabs(own);
      evidence_[static_cast<std::size_t>(m)] -= Real(0.5) * nu * nu / (noise2 + scale * scale);
    }
  }
  predicted_change_.fill(0);
  interval_count_ = 1;  // this sample starts the next interval
  interval_start_rate_ = estimate_.rotation_rate;
  interval_start_tilt_ = estimate_.tilt;
  interval_impact_ = false;
  interval_terminal_ = gyroscope_mode_.terminal();
  interval_moved_ = gyroscope_mode_.phase != Phase::kFullContact;
}

void StatueFilter::weigh(const Ensemble& members) {
  // Weights.
  Real best = evidence_[0];
  for (int m = 1; m < members_; ++m) best = std::fmax(best, evidence_[static_cast<std::size_t>(m)]);
  Real sum = 0;
  for (int m = 0; m < members_; ++m) {
    const auto k = static_cast<std::size_t>(m);
    estimate_.weights[k] = std::exp(evidence_[k] - best);
    sum += estimate_.weights[k];
  }
  Real sum2 = 0;
  for (int m = 0; m < members_; ++m) {
    Real& w = estimate_.weights[static_cast<std::size_t>(m)];
    w /= sum;
    sum2 += w * w;
  }
  estimate_.effective_members = Real(1) / sum2;
  estimate_.informative =
      members_ > 1 && estimate_.effective_members <=
                          settings_.informative_fraction * static_cast<Real>(members_);
  // Explained.
  estimate_.best_member = 0;
  estimate_.best_score = 0;
  for (int m = 0; m < members_; ++m) {
    const auto k = static_cast<std::size_t>(m);
    // A member with no signal yet explains everything so far (score 0).
    const Real mean = score_norm_[k] > 0 ? score_[k] / score_norm_[k] : Real(0);
    if (m == 0 || mean < estimate_.best_score) {
      estimate_.best_score = mean;
      estimate_.best_member = m;
    }
  }
  estimate_.span_score = span_score_norm_ > 0 ? span_score_ / span_score_norm_ : Real(0);
  estimate_.explained = span_score_norm_ < kMinScoredIntervals ||
                       estimate_.span_score < settings_.unexplained_score;
  // Ruled out: only while some member explains the motion (else every member stays).
  estimate_.ruled_out = 0;
  estimate_.ruled_out_members = 0;
  for (int m = 0; m < members_ && estimate_.explained; ++m) {
    if (estimate_.weights[static_cast<std::size_t>(m)] * static_cast<Real>(members_) <
        settings_.ruled_out_fraction) {
      ++estimate_.ruled_out;
      estimate_.ruled_out_members |= 1U << static_cast<unsigned>(m);
    }
  }

  // Risk: each member's at the measured phase and state.
  std::array<Real, kMaxEnsembleMembers> risks{};
  std::array<Risk, kMaxEnsembleMembers> member_risks{};
  for (int m = 0; m < members_; ++m) {
    const PlanarEstimator& e = members.member(m);
    Mode mode = estimate_.mode;
    mode.held_stop = e.mode().held_stop;
    const auto k = static_cast<std::size_t>(m);
    member_risks[k] = overturning_risk(e.scene(), mode, measured_state(e), risk_);
    risks[k] = member_risks[k].total;
  }
  estimate_.weighted = estimate_.informative && estimate_.explained;
  if (estimate_.weighted) {
    // The highest risk that members holding credible_weight reach: the members by risk, highest
    // first, until their weight adds up (at most kMaxEnsembleMembers: a selection each time).
    std::array<bool, kMaxEnsembleMembers> taken{};
    Real held = 0;
    int chosen = 0;
    for (int n = 0; n < members_ && held < settings_.credible_weight; ++n) {
      int top = -1;
      for (int m = 0; m < members_; ++m) {
        const auto k = static_cast<std::size_t>(m);
        if (!taken[k] && (top < 0 || risks[k] > risks[static_cast<std::size_t>(top)])) top = m;
      }
      taken[static_cast<std::size_t>(top)] = true;
      held += estimate_.weights[static_cast<std::size_t>(top)];
      chosen = top;
    }
    estimate_.risk = member_risks[static_cast<std::size_t>(chosen)];
    estimate_.risk_member = chosen;
    return;
  }
  // The worst member's not ruled out: of the measured state, and of its own simulation while
  // that agrees with the measured rate (a member just kicked into rocking by its base's stops
  // while the statue stands is contradicted at once, before its evidence's next interval).
  estimate_.risk = Risk{};
  estimate_.risk_member = -1;
  estimate_.disagreeing_members = 0;
  const Real noise2 = Real(2) * settings_.rate_noise_rad_s * settings_.rate_noise_rad_s;
  for (int m = 0; m < members_; ++m) {
    if ((estimate_.ruled_out_members >> static_cast<unsigned>(m) & 1U) != 0U) continue;
    const auto k = static_cast<std::size_t>(m);
    const PlanarEstimator& e = members.member(m);
    const Real own_rate = e.state()[kThetaDot];
    const Real nu = own_rate - estimate_.rotation_rate;
    const Real scale = settings_.model_tolerance *
                       std::fmax(std::fabs(own_rate), std::fabs(estimate_.rotation_rate));
    const bool agrees = !estimate_.explained || nu * nu <= kAgreement * kAgreement *
                                                               (noise2 + scale * scale);
    if (!agrees) estimate_.disagreeing_members |= 1U << static_cast<unsigned>(m);
    const Risk own = agrees ? overturning_risk(e.scene(), e.mode(), e.state(), risk_) : Risk{};
    const Risk& worse = own.total >= risks[k] ? own : member_risks[k];
    if (estimate_.risk_member < 0 || worse.total > estimate_.risk.total) {
      estimate_.risk = worse;
      estimate_.risk_member = m;
    }
  }
}

}  // namespace plinth
