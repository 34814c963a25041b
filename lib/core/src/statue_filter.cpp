#include "plinth/core/statue_filter.h"

#include <cmath>

#include "plinth/core/internal/flows.h"

namespace plinth {

namespace {

// A change of theta' over an interval is a signal beyond this many times one rate's noise.
constexpr Real kSignal = 4;
// A member's own theta' agrees with the measured one within this many standard deviations
// (the innovation's: noise and model tolerance).
constexpr Real kAgreement = 3;

bool positive_finite(double x) { return std::isfinite(x) && x > 0.0; }

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

Error validate(const StatueFilterSettings& s) {
  if (!positive_finite(s.rate_noise_rad_s)) {
    return {ErrorCode::kOutOfRange, "statue_filter.rate_noise_rad_s", "must be finite and > 0"};
  }
  if (!positive_finite(s.model_tolerance) || s.model_tolerance > 2) {
    return {ErrorCode::kOutOfRange, "statue_filter.model_tolerance", "must lie in (0, 2]"};
  }
  if (!positive_finite(s.rest_rate_rad_s)) {
    return {ErrorCode::kOutOfRange, "statue_filter.rest_rate_rad_s", "must be finite and > 0"};
  }
  if (!positive_finite(s.rest_tilt_rad) || s.rest_tilt_rad > Real(0.1)) {
    return {ErrorCode::kOutOfRange, "statue_filter.rest_tilt_rad", "must lie in (0, 0.1] rad"};
  }
  if (!positive_finite(s.rest_time_s)) {
    return {ErrorCode::kOutOfRange, "statue_filter.rest_time_s", "must be finite and > 0"};
  }
  if (!positive_finite(s.interval_s) || s.interval_s > 1.0) {
    return {ErrorCode::kOutOfRange, "statue_filter.interval_s", "must lie in (0, 1] s"};
  }
  if (!positive_finite(s.memory_s)) {
    return {ErrorCode::kOutOfRange, "statue_filter.memory_s", "must be finite and > 0"};
  }
  if (!positive_finite(s.score_memory_s)) {
    return {ErrorCode::kOutOfRange, "statue_filter.score_memory_s", "must be finite and > 0"};
  }
  if (!positive_finite(s.informative_fraction) || s.informative_fraction > 1) {
    return {ErrorCode::kOutOfRange, "statue_filter.informative_fraction", "must lie in (0, 1]"};
  }
  if (!positive_finite(s.credible_weight) || s.credible_weight > 1) {
    return {ErrorCode::kOutOfRange, "statue_filter.credible_weight", "must lie in (0, 1]"};
  }
  if (!positive_finite(s.unexplained_score)) {
    return {ErrorCode::kOutOfRange, "statue_filter.unexplained_score", "must be finite and > 0"};
  }
  if (!positive_finite(s.ruled_out_fraction) || s.ruled_out_fraction > 1) {
    return {ErrorCode::kOutOfRange, "statue_filter.ruled_out_fraction", "must lie in (0, 1]"};
  }
  return ok_error();
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
  if (estimate.weighted) return static_cast<double>(p);
  return counted > 0 ? static_cast<double>(p) / counted : forecast.probability;
}

Error StatueFilter::start(const StatueFilterSettings& settings, const EstimatorSettings& rate,
                          const RiskSettings& risk, int members) {
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
  have_previous_ = false;
}

// The measured state as member `member` would have it: its own base and sliding (not measured),
// the measured rotation.
State StatueFilter::measured_state(const PlanarEstimator& member) const {
  State y = member.state();
  y[kTheta] = estimate_.tilt;
  y[kThetaDot] = estimate_.rotation_rate;
  return y;
}

// The tilt (the rate integrated by the trapezoid rule, back to 0 once still and nearly upright)
// and the phase.
void StatueFilter::measure(const Ensemble& members, const StatueMeasurement& measured) {
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
  // back on its base (what the integrated rate says otherwise is the gyroscope's drift).
  if (still_samples_ >= rest_samples_ && std::fabs(tilt) < Real(0.5) * smallest_critical) {
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
  if (mode.rocking() && estimate_.mode.rocking() && mode.corner != estimate_.mode.corner) {
    interval_impact_ = true;
  }
  if (mode.terminal()) interval_terminal_ = true;
  if (mode.phase != Phase::kFullContact) interval_moved_ = true;
  estimate_.mode = mode;
  estimate_.tilt = tilt;
  estimate_.rotation_rate = rate;
  previous_rate_ = rate;
}

void StatueFilter::on_sample(const Ensemble& members, GroundAcceleration ground,
                             const StatueMeasurement& measured) {
  if (members_ == 0 || members.size() != members_) return;
  if (!std::isfinite(measured.rotation_rate)) return;  // the conditioning passes none
  measure(members, measured);
  if (!have_previous_ || interval_count_ == 0) {
    interval_start_rate_ = estimate_.rotation_rate;
    interval_start_tilt_ = estimate_.tilt;
  }
  for (int m = 0; m < members_; ++m) {
    const PlanarEstimator& e = members.member(m);
    const bool base_moves = e.scene().has_base() && e.mode().held_stop == 0;
    const Real a = rotational_acceleration(e.scene(), estimate_.mode, measured_state(e),
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
}

void StatueFilter::finish_interval(const Ensemble& members) {
  const Real measured_change = estimate_.rotation_rate - interval_start_rate_;
  if (!interval_impact_ && !interval_terminal_) {
    const Real noise2 = Real(2) * settings_.rate_noise_rad_s * settings_.rate_noise_rad_s;
    for (int m = 0; m < members_; ++m) {
      const auto k = static_cast<std::size_t>(m);
      const Real predicted = predicted_change_[k];
      const Real nu = measured_change - predicted;
      const Real scale =
          settings_.model_tolerance * std::fmax(std::fabs(predicted), std::fabs(measured_change));
      const Real s2 = noise2 + scale * scale;
      const Real chi2 = nu * nu / s2;
      evidence_[k] = evidence_[k] * evidence_decay_ - Real(0.5) * chi2 - Real(0.5) * std::log(s2);
      // The score counts intervals with a change beyond the noise, measured or predicted: an
      // interval where nothing moves and nothing should says nothing about the model.
      if (scale > settings_.model_tolerance * kSignal * settings_.rate_noise_rad_s) {
        score_[k] = score_[k] * score_decay_ + chi2;
        score_norm_[k] = score_norm_[k] * score_decay_ + 1;
      }
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
  interval_terminal_ = estimate_.mode.terminal();
  interval_moved_ = estimate_.mode.phase != Phase::kFullContact;
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
  estimate_.explained = estimate_.best_score < settings_.unexplained_score;
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
