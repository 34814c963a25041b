#include "plinth/monitor/p_wave.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "plinth/core/checks.h"
#include "plinth/core/scene.h"
#include "settings_checks.h"

namespace plinth::monitor {

namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kButterworthDamping = std::numbers::sqrt2_v<Real>;

// A positive finite time, in seconds, below kMaxDurationS.
Error check_time(Time seconds, const char* field) {
  return detail::check_duration(seconds, field, false);
}

Error check_predictor(const PWaveSettings& s) {
  if (s.predictor_points < 1 || s.predictor_points > kMaxPWavePredictorPoints) {
    return {ErrorCode::kOutOfRange, "pwave.predictor", "must have 1 to 8 points",
            static_cast<double>(kMaxPWavePredictorPoints)};
  }
  for (std::size_t i = 0; i < s.predictor_points; ++i) {
    const PWavePredictorPoint& p = s.predictor[i];
    PLINTH_TRY(check_time(p.window_s, "pwave.predictor.window_s"));
    if (i > 0 && !(p.window_s > s.predictor[i - 1].window_s)) {
      return {ErrorCode::kInconsistent, "pwave.predictor.window_s",
              "must increase from point to point", s.predictor[i - 1].window_s};
    }
    if (!std::isfinite(p.ln_pga_over_pa)) {
      return {ErrorCode::kNotFinite, "pwave.predictor.ln_pga_over_pa", "must be finite"};
    }
    if (!std::isfinite(p.tau_c_exponent)) {
      return {ErrorCode::kNotFinite, "pwave.predictor.tau_c_exponent", "must be finite"};
    }
    PLINTH_TRY(check_positive(p.sigma_ln, "pwave.predictor.sigma_ln"));
  }
  return ok_error();
}

Error check_order(bool ordered, const char* field, const char* reason, double limit) {
  if (ordered) return ok_error();
  return {ErrorCode::kInconsistent, field, reason, limit};
}

// Per-sample gain of an exponential average over `tau_s`: 1 - exp(-T / tau).
Real average_gain(Time period_s, Time tau_s) {
  return static_cast<Real>(-std::expm1(-period_s / tau_s));
}

std::int64_t samples_in(Time seconds, Time period_s) {
  return static_cast<std::int64_t>(std::llround(seconds / period_s));
}

}  // namespace

Error validate(const PWaveSettings& s) {
  PLINTH_TRY(detail::first_error({
      check_time(s.sample_period_s, "pwave.sample_period_s"),
      check_positive(s.highpass_hz, "pwave.highpass_hz"),
      check_positive(s.lowpass_hz, "pwave.lowpass_hz"),
      check_time(s.sta_s, "pwave.sta_s"),
      check_time(s.lta_s, "pwave.lta_s"),
      check_positive(s.trigger_ratio, "pwave.trigger_ratio"),
      check_positive(s.detrigger_ratio, "pwave.detrigger_ratio"),
      check_positive(s.noise_floor_m_s2, "pwave.noise_floor_m_s2"),
      check_positive(s.min_amplitude_m_s2, "pwave.min_amplitude_m_s2"),
      check_time(s.confirm_s, "pwave.confirm_s"),
      check_time(s.max_retry_s, "pwave.max_retry_s"),
      check_time(s.min_tau_p_s, "pwave.min_tau_p_s"),
      check_time(s.max_tau_c_s, "pwave.max_tau_c_s"),
      check_positive(s.min_vertical_ratio, "pwave.min_vertical_ratio"),
      check_positive(s.s_wave_ratio, "pwave.s_wave_ratio"),
      check_time(s.max_window_s, "pwave.max_window_s"),
      check_time(s.hold_s, "pwave.hold_s"),
  }));
  if (static_cast<std::uint8_t>(s.channel) > static_cast<std::uint8_t>(PWaveChannel::kHorizontal)) {
    return {ErrorCode::kOutOfRange, "pwave.channel", "must be vertical or horizontal", 1.0};
  }
  const double nyquist_hz = 0.5 / s.sample_period_s;
  PLINTH_TRY(detail::first_error({
      check_order(static_cast<double>(s.lowpass_hz) < nyquist_hz, "pwave.lowpass_hz",
                  "must be below half the sample rate", nyquist_hz),
      check_order(s.highpass_hz < s.lowpass_hz, "pwave.highpass_hz",
                  "must be below pwave.lowpass_hz", s.lowpass_hz),
      check_order(s.sta_s < s.lta_s, "pwave.sta_s", "must be shorter than pwave.lta_s", s.lta_s),
      check_order(s.trigger_ratio > Real(1), "pwave.trigger_ratio", "must exceed 1", 1.0),
      check_order(s.detrigger_ratio < s.trigger_ratio, "pwave.detrigger_ratio",
                  "must be below pwave.trigger_ratio", s.trigger_ratio),
      check_order(s.sta_s >= s.sample_period_s, "pwave.sta_s",
                  "must be at least one sample period", s.sample_period_s),
      check_order(s.confirm_s >= 2.0 * s.sample_period_s, "pwave.confirm_s",
                  "must be at least two sample periods", 2.0 * s.sample_period_s),
      check_order(s.confirm_s <= s.max_window_s, "pwave.confirm_s",
                  "must not exceed pwave.max_window_s", s.max_window_s),
      check_order(s.min_tau_p_s < s.max_tau_c_s, "pwave.min_tau_p_s",
                  "must be below pwave.max_tau_c_s", s.max_tau_c_s),
  }));
  PLINTH_TRY(check_predictor(s));
  return s.fragility_known ? detail::check_fragility(s.fragility) : ok_error();
}

void detail::StateVariableFilter::design(Real corner_hz, Time period_s) {
  g = static_cast<Real>(
      std::tan(static_cast<double>(kPi) * static_cast<double>(corner_hz) * period_s));
  k = kButterworthDamping;
  h = Real(1) / (Real(1) + k * g + g * g);
  w = static_cast<Real>(2.0 * static_cast<double>(g) / period_s);
  clear();
}

detail::StateVariableFilter::Out detail::StateVariableFilter::step(Real x) {
  Out o;
  o.high = (x - (k + g) * s1 - s2) * h;
  const Real v1 = g * o.high;
  o.band = v1 + s1;
  s1 = o.band + v1;
  const Real v2 = g * o.band;
  o.low = v2 + s2;
  s2 = o.low + v2;
  return o;
}

void detail::PWaveChannelFilter::design(const PWaveSettings& s) {
  lowpass.design(s.lowpass_hz, s.sample_period_s);
  highpass.design(s.highpass_hz, s.sample_period_s);
  velocity.design(s.highpass_hz, s.sample_period_s);
  displacement.design(s.highpass_hz, s.sample_period_s);
  a = v = d = Real(0);
}

// HP(s) / s = band(s) / w: the high-passed integral (Kanamori's recursive integration and
// 0.075 Hz high-pass in one well-conditioned filter).
void detail::PWaveChannelFilter::step_acceleration(Real x) {
  a = highpass.step(lowpass.step(x).low).high;
}

void detail::PWaveChannelFilter::step_integration() {
  v = velocity.step(a).band / velocity.w;
  d = displacement.step(v).band / displacement.w;
}

void detail::PWaveChannelFilter::start_integration() {
  velocity.clear();
  displacement.clear();
  v = d = Real(0);
}

void detail::PWaveChannelFilter::clear() {
  lowpass.clear();
  highpass.clear();
  start_integration();
  a = Real(0);
}

Error PWaveStage::create(const PWaveSettings& settings, PWaveStage& out) {
  PLINTH_TRY(validate(settings));
  out = PWaveStage{};
  out.settings_ = settings;
  out.sta_gain_ = average_gain(settings.sample_period_s, settings.sta_s);
  out.lta_gain_ = average_gain(settings.sample_period_s, settings.lta_s);
  out.floor_energy_ = settings.noise_floor_m_s2 * settings.noise_floor_m_s2;
  out.min_energy_ = settings.min_amplitude_m_s2 * settings.min_amplitude_m_s2;
  out.confirm_samples_ = samples_in(settings.confirm_s, settings.sample_period_s);
  out.max_retry_samples_ = samples_in(settings.max_retry_s, settings.sample_period_s);
  out.max_window_samples_ = samples_in(settings.max_window_s, settings.sample_period_s);
  out.hold_samples_ = samples_in(settings.hold_s, settings.sample_period_s);
  for (detail::PWaveChannelFilter& f : out.filters_) f.design(settings);
  return ok_error();
}

void PWaveStage::restart() {
  for (detail::PWaveChannelFilter& f : filters_) f.clear();
  sta_ = lta_ = Real(0);
  sample_ = 0;
  state_since_ = 0;
  excited_ = excitation_refused_ = false;
  excitation_since_ = 0;
  sum_d2_ = sum_v2_ = sum_a2_ = peak_a_ = peak_v_ = peak_d_ = peak_h_ = Real(0);
  PWaveStatus fresh;
  fresh.candidates = status_.candidates;
  fresh.triggers = status_.triggers;
  fresh.rejected_short = status_.rejected_short;
  fresh.rejected_long = status_.rejected_long;
  fresh.rejected_horizontal = status_.rejected_horizontal;
  fresh.rejected_not_after_quiet = status_.rejected_not_after_quiet;
  status_ = fresh;
}

PWavePredictorPoint PWaveStage::predictor_at(Time window_s) const {
  const auto& table = settings_.predictor;
  const std::size_t n = settings_.predictor_points;
  if (window_s <= table[0].window_s) return table[0];
  if (window_s >= table[n - 1].window_s) return table[n - 1];
  std::size_t i = 1;
  while (table[i].window_s < window_s) ++i;
  const PWavePredictorPoint& lo = table[i - 1];
  const PWavePredictorPoint& hi = table[i];
  const auto f = static_cast<Real>((window_s - lo.window_s) / (hi.window_s - lo.window_s));
  return {window_s, lo.ln_pga_over_pa + f * (hi.ln_pga_over_pa - lo.ln_pga_over_pa),
          lo.tau_c_exponent + f * (hi.tau_c_exponent - lo.tau_c_exponent),
          lo.sigma_ln + f * (hi.sigma_ln - lo.sigma_ln)};
}

Real PWaveStage::predicted_ln_pga(Real pa_m_s2, Real tau_c_s, Time window_s) const {
  const PWavePredictorPoint p = predictor_at(window_s);
  return std::log(pa_m_s2) + p.ln_pga_over_pa + p.tau_c_exponent * std::log(tau_c_s);
}

// The fragility under the prediction's lognormal scatter (fragility.h).
Real PWaveStage::collapse_probability(Real predicted_pga_g, Real sigma_ln) const {
  if (!settings_.fragility_known) return Real(0);
  return settings_.fragility.probability(predicted_pga_g, sigma_ln);
}

Real PWaveStage::window_tau_c() const {
  if (!(sum_v2_ > Real(0))) return Real(0);
  return Real(2) * kPi * std::sqrt(sum_d2_ / sum_v2_);
}

Real PWaveStage::window_tau_p() const {
  if (!(sum_a2_ > Real(0))) return Real(0);
  return Real(2) * kPi * std::sqrt(sum_v2_ / sum_a2_);
}

void PWaveStage::start_candidate() {
  for (detail::PWaveChannelFilter& f : filters_) f.start_integration();
  status_.state = PWaveState::kCandidate;
  state_since_ = sample_;
  ++status_.candidates;
  sum_d2_ = sum_v2_ = sum_a2_ = peak_a_ = peak_v_ = peak_d_ = peak_h_ = Real(0);
}

// A candidate out of quiet begins an excitation; a retry starts within max_retry_s of its
// first candidate, or the excitation is refused (p_wave.h: the shaking under way).
void PWaveStage::start_or_refuse_candidate() {
  if (!excited_) {
    excited_ = true;
    excitation_refused_ = false;
    excitation_since_ = sample_;
    status_.excitation_onset_s = static_cast<Time>(sample_ - 1) * settings_.sample_period_s;
  } else if (sample_ - excitation_since_ > max_retry_samples_) {
    if (!excitation_refused_) {
      excitation_refused_ = true;
      ++status_.rejected_not_after_quiet;
      status_.last_rejection = PWaveRejection::kNotAfterQuiet;
    }
    return;
  }
  start_candidate();
}

void PWaveStage::judge_candidate() {
  const Real tau_c = window_tau_c();
  PWaveRejection rejection = PWaveRejection::kNone;
  if (static_cast<Time>(window_tau_p()) < settings_.min_tau_p_s) {
    rejection = PWaveRejection::kPeriodShort;
    ++status_.rejected_short;
  } else if (static_cast<Time>(tau_c) > settings_.max_tau_c_s) {
    rejection = PWaveRejection::kPeriodLong;
    ++status_.rejected_long;
  } else if (settings_.channel == PWaveChannel::kVertical &&
             peak_a_ < settings_.min_vertical_ratio * peak_h_) {
    rejection = PWaveRejection::kHorizontal;
    ++status_.rejected_horizontal;
  }
  status_.last_rejection = rejection;
  if (rejection != PWaveRejection::kNone) {
    status_.state = PWaveState::kIdle;
    state_since_ = sample_;
    return;
  }
  // A new event: its parameters and probability start afresh; its excitation is spent (after
  // the hold a candidate starts a new one).
  excited_ = false;
  ++status_.triggers;
  status_.state = PWaveState::kWindow;
  status_.onset_s = static_cast<Time>(state_since_ - 1) * settings_.sample_period_s;
  status_.window_end = PWaveWindowEnd::kNone;
  status_.probability = Real(0);
  update_window();
}

// The parameters over the window, the prediction and the probability.
void PWaveStage::update_window() {
  const std::int64_t window_samples = sample_ - state_since_;
  status_.window_s = static_cast<Time>(window_samples) * settings_.sample_period_s;
  status_.pa_m_s2 = peak_a_;
  status_.pv_m_s = peak_v_;
  status_.pd_m = peak_d_;
  status_.tau_c_s = window_tau_c();
  status_.tau_p_s = window_tau_p();
  status_.horizontal_m_s2 = peak_h_;
  if (peak_a_ > Real(0) && status_.tau_c_s > Real(0)) {
    const Real ln_pga = predicted_ln_pga(peak_a_, status_.tau_c_s, status_.window_s);
    status_.predicted_pga_g = std::exp(ln_pga) / kStandardGravity;
    status_.sigma_ln = predictor_at(status_.window_s).sigma_ln;
    status_.probability = std::max(status_.probability,
                                   collapse_probability(status_.predicted_pga_g, status_.sigma_ln));
  }
  if (settings_.channel == PWaveChannel::kVertical &&
      peak_h_ >= settings_.s_wave_ratio * peak_a_) {
    close_window(PWaveWindowEnd::kSWave);
  } else if (window_samples >= max_window_samples_) {
    close_window(PWaveWindowEnd::kMaxWindow);
  }
}

void PWaveStage::close_window(PWaveWindowEnd end) {
  status_.window_end = end;
  status_.state = PWaveState::kHolding;
  state_since_ = sample_;
}

const PWaveStatus& PWaveStage::update(const Vector3r& ground_m_s2) {
  if (!ground_m_s2.allFinite()) {
    ++refused_;
    return status_;
  }
  for (int axis = 0; axis < 3; ++axis) {
    filters_[static_cast<std::size_t>(axis)].step_acceleration(ground_m_s2[axis]);
  }
  detail::PWaveChannelFilter& x = filters_[0];
  detail::PWaveChannelFilter& y = filters_[1];
  detail::PWaveChannelFilter& z = filters_[2];
  const Real horizontal_a2 = x.a * x.a + y.a * y.a;
  const bool vertical = settings_.channel == PWaveChannel::kVertical;
  const Real energy = vertical ? z.a * z.a : horizontal_a2;
  ++sample_;
  sta_ += sta_gain_ * (energy - sta_);
  const bool lta_frozen =
      status_.state == PWaveState::kCandidate || status_.state == PWaveState::kWindow;
  if (!lta_frozen) lta_ += lta_gain_ * (energy - lta_);
  status_.sta_lta = sta_ / std::max(lta_, floor_energy_);

  if (status_.state == PWaveState::kHolding && sample_ - state_since_ >= hold_samples_) {
    status_.state = PWaveState::kIdle;
    state_since_ = sample_;
    status_.probability = Real(0);
  }
  if (status_.state == PWaveState::kIdle) {
    if (status_.sta_lta < settings_.detrigger_ratio) excited_ = false;  // quiet again
    if (status_.sta_lta >= settings_.trigger_ratio && sta_ >= min_energy_) {
      start_or_refuse_candidate();
    }
  }
  if (status_.state == PWaveState::kCandidate || status_.state == PWaveState::kWindow) {
    for (detail::PWaveChannelFilter& f : filters_) f.step_integration();
    const Real v2 = vertical ? z.v * z.v : x.v * x.v + y.v * y.v;
    const Real d2 = vertical ? z.d * z.d : x.d * x.d + y.d * y.d;
    sum_d2_ += d2;
    sum_v2_ += v2;
    sum_a2_ += energy;
    peak_a_ = std::max(peak_a_, std::sqrt(energy));
    peak_v_ = std::max(peak_v_, std::sqrt(v2));
    peak_d_ = std::max(peak_d_, std::sqrt(d2));
    peak_h_ = std::max(peak_h_, std::sqrt(horizontal_a2));
  }
  if (status_.state == PWaveState::kCandidate) {
    if (sample_ - state_since_ >= confirm_samples_) judge_candidate();
  } else if (status_.state == PWaveState::kWindow) {
    update_window();
  }
  return status_;
}

}  // namespace plinth::monitor
