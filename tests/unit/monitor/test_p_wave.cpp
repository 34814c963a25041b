// The on-site P-wave stage (p_wave.h): its filters against the bilinear transform's closed
// forms, the trigger and its discriminants on synthetic P and S waves, the early parameters,
// the prediction and the probability of collapse, and no trigger on footsteps, doors, traffic
// and bumps of the plinth (nuisance_signals.h).
#include "plinth/monitor/p_wave.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "nuisance_signals.h"
#include "plinth/core/scene.h"
#include "settings_support.h"

namespace plinth::monitor {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kGravity = kStandardGravity;

PWaveSettings at_rate(double rate_hz) {
  PWaveSettings s;
  s.sample_period_s = 1.0 / rate_hz;
  return s;
}

PWaveStage make(const PWaveSettings& s) {
  PWaveStage stage;
  const Error e = PWaveStage::create(s, stage);
  EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  return stage;
}

// ---------------------------------------------------------------------------------------------
// Settings

void expect_refused(const PWaveSettings& s, const char* field, ErrorCode code,
                    const char* reason_part = nullptr) {
  plinth::testing::expect_create_refused<PWaveStage>(s, field, code, reason_part);
}

TEST(PWaveSettings, DefaultsAreValidAndEveryFieldIsChecked) {
  EXPECT_TRUE(validate(PWaveSettings{}).ok());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PWaveSettings s;
  s.sample_period_s = 0.0;
  expect_refused(s, "pwave.sample_period_s", ErrorCode::kOutOfRange);
  s = {};
  s.highpass_hz = nan;
  expect_refused(s, "pwave.highpass_hz", ErrorCode::kNotFinite);
  s = {};
  s.lowpass_hz = -1.0;
  expect_refused(s, "pwave.lowpass_hz", ErrorCode::kOutOfRange);
  s = at_rate(200.0);
  s.lowpass_hz = 100.0;
  expect_refused(s, "pwave.lowpass_hz", ErrorCode::kInconsistent, "half the sample rate");
  s = {};
  s.highpass_hz = 5.0;
  expect_refused(s, "pwave.highpass_hz", ErrorCode::kInconsistent, "lowpass_hz");
  s = {};
  s.sta_s = 20.0;
  expect_refused(s, "pwave.sta_s", ErrorCode::kInconsistent, "lta_s");
  s = {};
  s.lta_s = 2e6;
  expect_refused(s, "pwave.lta_s", ErrorCode::kOutOfRange);
  s = {};
  s.trigger_ratio = 1.0;
  expect_refused(s, "pwave.trigger_ratio", ErrorCode::kInconsistent);
  s = {};
  s.noise_floor_m_s2 = 0.0;
  expect_refused(s, "pwave.noise_floor_m_s2", ErrorCode::kOutOfRange);
  s = {};
  s.min_amplitude_m_s2 = std::numeric_limits<double>::infinity();
  expect_refused(s, "pwave.min_amplitude_m_s2", ErrorCode::kNotFinite);
  s = {};
  s.confirm_s = 5.0;
  expect_refused(s, "pwave.confirm_s", ErrorCode::kInconsistent, "max_window_s");
  s = {};
  s.detrigger_ratio = 0.0;
  expect_refused(s, "pwave.detrigger_ratio", ErrorCode::kOutOfRange);
  s = {};
  s.detrigger_ratio = 8.0;
  expect_refused(s, "pwave.detrigger_ratio", ErrorCode::kInconsistent, "trigger_ratio");
  s = {};
  s.max_retry_s = 0.0;
  expect_refused(s, "pwave.max_retry_s", ErrorCode::kOutOfRange);
  s = {};
  s.max_retry_s = nan;
  expect_refused(s, "pwave.max_retry_s", ErrorCode::kNotFinite);
  s = {};
  s.min_tau_p_s = 20.0;
  expect_refused(s, "pwave.min_tau_p_s", ErrorCode::kInconsistent, "max_tau_c_s");
  s = {};
  s.max_tau_c_s = -1.0;
  expect_refused(s, "pwave.max_tau_c_s", ErrorCode::kOutOfRange);
  s = {};
  s.min_vertical_ratio = 0.0;
  expect_refused(s, "pwave.min_vertical_ratio", ErrorCode::kOutOfRange);
  s = {};
  s.s_wave_ratio = nan;
  expect_refused(s, "pwave.s_wave_ratio", ErrorCode::kNotFinite);
  s = {};
  s.max_window_s = 0.0;
  expect_refused(s, "pwave.max_window_s", ErrorCode::kOutOfRange);
  s = {};
  s.hold_s = -1.0;
  expect_refused(s, "pwave.hold_s", ErrorCode::kOutOfRange);
  s = {};
  s.channel = static_cast<PWaveChannel>(9);
  expect_refused(s, "pwave.channel", ErrorCode::kOutOfRange);
  s = {};
  s.predictor_points = 0;
  expect_refused(s, "pwave.predictor", ErrorCode::kOutOfRange);
  s = {};
  s.predictor[3].window_s = s.predictor[2].window_s;
  expect_refused(s, "pwave.predictor.window_s", ErrorCode::kInconsistent, "increase");
  s = {};
  s.predictor[1].ln_pga_over_pa = nan;
  expect_refused(s, "pwave.predictor.ln_pga_over_pa", ErrorCode::kNotFinite);
  s = {};
  s.predictor[1].tau_c_exponent = nan;
  expect_refused(s, "pwave.predictor.tau_c_exponent", ErrorCode::kNotFinite);
  s = {};
  s.predictor[0].sigma_ln = 0.0;
  expect_refused(s, "pwave.predictor.sigma_ln", ErrorCode::kOutOfRange);
  s = {};
  s.fragility_known = true;
  s.fragility = {0.0, 0.4};
  expect_refused(s, "fragility.median_g", ErrorCode::kOutOfRange);
  s.fragility = {0.5, -0.1};
  expect_refused(s, "fragility.beta", ErrorCode::kOutOfRange);
  s.fragility_known = false;  // an unknown fragility is not checked
  EXPECT_TRUE(validate(s).ok());
}

// ---------------------------------------------------------------------------------------------
// Filters: the bilinear transform maps the analog prototype H(s) to the digital filter whose
// response at frequency f is H(j W), W = (2 / T) tan(pi f T), exactly.

using Complex = std::complex<double>;

// The analog 2nd-order Butterworth sections, corner prewarped like the filter's.
Complex section(double w_corner, Complex s, double numerator_power) {
  return std::pow(s, numerator_power) * std::pow(w_corner, 2.0 - numerator_power) /
         (s * s + std::numbers::sqrt2 * w_corner * s + w_corner * w_corner);
}

struct ChannelResponse {
  Complex a, v, d;
};

ChannelResponse closed_form(const PWaveSettings& p, double f_hz) {
  const double t = p.sample_period_s;
  const Complex s(0.0, 2.0 / t * std::tan(kPi * f_hz * t));
  const double w_low = 2.0 / t * std::tan(kPi * p.lowpass_hz * t);
  const double w_high = 2.0 / t * std::tan(kPi * p.highpass_hz * t);
  const Complex low = section(w_low, s, 0.0);
  const Complex high = section(w_high, s, 2.0);
  const Complex band_over_w = section(w_high, s, 1.0) / w_high;  // HP(s) / s
  return {low * high, low * high * band_over_w, low * high * band_over_w * band_over_w};
}

TEST(PWaveFilters, SteadySineMatchesTheBilinearClosedForms) {
  for (const double rate : {200.0, 1000.0}) {
    for (const double f : {0.3, 1.0, 2.0}) {
      const PWaveSettings p = at_rate(rate);
      detail::PWaveChannelFilter filter;
      filter.design(p);
      const double amplitude = 0.7;  // m/s2
      const auto settle = static_cast<std::size_t>(60.0 * rate);  // 0.075 Hz: 60 s is 30 tau
      const auto cycles = static_cast<std::size_t>(4.0 / f * rate);
      double peak_a = 0, peak_v = 0, peak_d = 0, sum_v2 = 0, sum_d2 = 0;
      for (std::size_t i = 0; i < settle + cycles; ++i) {
        filter.step_acceleration(
            static_cast<Real>(amplitude * std::sin(2.0 * kPi * f * static_cast<double>(i) / rate)));
        filter.step_integration();
        if (i < settle) continue;
        peak_a = std::max(peak_a, std::fabs(double(filter.a)));
        peak_v = std::max(peak_v, std::fabs(double(filter.v)));
        peak_d = std::max(peak_d, std::fabs(double(filter.d)));
        sum_v2 += double(filter.v) * filter.v;
        sum_d2 += double(filter.d) * filter.d;
      }
      const ChannelResponse h = closed_form(p, f);
      SCOPED_TRACE("rate " + std::to_string(rate) + " Hz, f " + std::to_string(f) + " Hz");
      // Sampled peaks of a sine are within 1 - cos(pi f T) of its amplitude.
      const double sampling = 1.0 - std::cos(kPi * f / rate) + 1e-6;
      EXPECT_NEAR(peak_a / (amplitude * std::abs(h.a)), 1.0, sampling);
      EXPECT_NEAR(peak_v / (amplitude * std::abs(h.v)), 1.0, sampling);
      EXPECT_NEAR(peak_d / (amplitude * std::abs(h.d)), 1.0, sampling);
      // tau_c of a sine: 2 pi |d| / |v|, and 1 / f well inside the band.
      const double tau_c = 2.0 * kPi * std::sqrt(sum_d2 / sum_v2);
      EXPECT_NEAR(tau_c, 2.0 * kPi * std::abs(h.d) / std::abs(h.v), 1e-3 * tau_c);
      EXPECT_NEAR(tau_c * f, 1.0, 0.02);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// A synthetic earthquake at the sensor: quiet (1 mg of noise), then a P wave (vertical at
// f_p with a 0.5 s rise, horizontal 0.3 of it), then the S waves (horizontal, 5 times the P's
// vertical amplitude). Accelerations in m/s2, statue frame, z = v_G''.
struct SyntheticQuake {
  double rate_hz = 200.0;
  double p_at_s = 20.0;
  double p_amplitude_m_s2 = 0.3;
  double p_hz = 1.0;
  double s_after_p_s = 6.0;  // negative: no S waves
  double s_amplitude_m_s2 = 1.5;  // horizontal
  double seconds = 60.0;
  double noise_m_s2 = 0.01;

  [[nodiscard]] std::vector<Vector3r> samples() const {
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, noise_m_s2);
    std::vector<Vector3r> out;
    for (std::size_t i = 0; i < static_cast<std::size_t>(seconds * rate_hz); ++i) {
      const double t = static_cast<double>(i) / rate_hz;
      Vector3r a(noise(rng), noise(rng), noise(rng));
      const double tp = t - p_at_s;
      if (tp >= 0.0) {
        const double rise = std::min(1.0, tp / 0.5);
        a.z() += p_amplitude_m_s2 * rise * std::sin(2.0 * kPi * p_hz * tp);
        a.x() += 0.3 * p_amplitude_m_s2 * rise * std::sin(2.0 * kPi * 0.7 * p_hz * tp);
      }
      const double ts = tp - s_after_p_s;
      if (s_after_p_s >= 0.0 && ts >= 0.0) {
        a.x() += s_amplitude_m_s2 * std::min(1.0, ts / 0.3) * std::sin(2.0 * kPi * 1.2 * ts);
      }
      out.push_back(a);
    }
    return out;
  }
};

struct Trace {
  std::vector<PWaveStatus> status;
  [[nodiscard]] const PWaveStatus& at(double t, double rate) const {
    return status[static_cast<std::size_t>(t * rate)];
  }
};

Trace run(PWaveStage& stage, const std::vector<Vector3r>& samples) {
  Trace trace;
  for (const Vector3r& a : samples) trace.status.push_back(stage.update(a));
  return trace;
}

// The event's highest probability over a run.
double highest_probability(const Trace& trace) {
  double highest = 0.0;
  for (const PWaveStatus& s : trace.status) highest = std::max(highest, double(s.probability));
  return highest;
}

PWaveSettings with_fragility(double rate_hz, double median_g, double beta) {
  PWaveSettings s = at_rate(rate_hz);
  s.fragility_known = true;
  s.fragility = {median_g, beta};
  return s;
}

TEST(PWaveStage, TriggersOnAPWaveJustAfterItsOnset) {
  const SyntheticQuake quake;
  PWaveStage stage = make(with_fragility(quake.rate_hz, 0.5, 0.4));
  const Trace trace = run(stage, quake.samples());
  const PWaveStatus& end = trace.status.back();
  EXPECT_EQ(end.triggers, 1U);
  EXPECT_EQ(end.candidates, 1U) << "rejected " << end.rejected_short << " short, "
                                << end.rejected_horizontal << " horizontal";
  // The onset: within the STA's reach after the P wave's start.
  EXPECT_GE(end.onset_s, quake.p_at_s);
  EXPECT_LE(end.onset_s, quake.p_at_s + 0.3);
  // Idle before the P wave, a candidate for confirm_s, then the window.
  EXPECT_EQ(trace.at(quake.p_at_s - 0.1, quake.rate_hz).state, PWaveState::kIdle);
  EXPECT_EQ(trace.at(end.onset_s + 0.25, quake.rate_hz).state, PWaveState::kCandidate);
  EXPECT_EQ(trace.at(end.onset_s + 1.0, quake.rate_hz).state, PWaveState::kWindow);
  EXPECT_GT(trace.at(end.onset_s + 1.0, quake.rate_hz).probability, 0.0);
  // The S waves come 6 s after the P wave: the window ends first, at max_window_s.
  EXPECT_EQ(end.window_end, PWaveWindowEnd::kMaxWindow);
}

TEST(PWaveStage, SWavesBeforeTheWindowsEndCloseIt) {
  SyntheticQuake quake;
  quake.s_after_p_s = 2.5;
  PWaveStage stage = make(with_fragility(quake.rate_hz, 0.5, 0.4));
  const Trace trace = run(stage, quake.samples());
  const PWaveStatus& end = trace.status.back();
  ASSERT_EQ(end.triggers, 1U);
  EXPECT_EQ(end.window_end, PWaveWindowEnd::kSWave);
  // Closed soon after the S waves' start (their horizontal passes 1.5 x the P's vertical peak
  // within their 0.3 s rise), and the window held from then on.
  const double closed_at = end.onset_s + end.window_s;
  EXPECT_GT(closed_at, quake.p_at_s + quake.s_after_p_s);
  EXPECT_LT(closed_at, quake.p_at_s + quake.s_after_p_s + 0.4);
  EXPECT_EQ(trace.at(closed_at + 1.0, quake.rate_hz).state, PWaveState::kHolding);
  EXPECT_EQ(trace.at(closed_at + 1.0, quake.rate_hz).pa_m_s2, end.pa_m_s2);
}

// An independent implementation of the stage's filters: direct-form biquads whose coefficients
// are the bilinear transform (s = K (1 - z^-1) / (1 + z^-1), K = 2 / T) of the same analog
// sections written out by hand, in double.
struct Biquad {
  std::array<double, 3> b{};
  std::array<double, 3> a{};  // a[0] = 1
  double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  // H(s) = (n2 s^2 + n1 s + n0) / (s^2 + sqrt2 w s + w^2), w prewarped to corner_hz.
  static Biquad bilinear(double n2, double n1, double n0, double corner_hz, double period_s) {
    const double k = 2.0 / period_s;
    const double w = k * std::tan(kPi * corner_hz * period_s);
    const auto scale = [&](double c2, double c1, double c0) {
      return std::array<double, 3>{c2 * k * k + c1 * k + c0, -2.0 * c2 * k * k + 2.0 * c0,
                                   c2 * k * k - c1 * k + c0};
    };
    Biquad f;
    const std::array<double, 3> den = scale(1.0, std::numbers::sqrt2 * w, w * w);
    // The numerator's coefficients are given in units of w: n1 w s, n0 w^2.
    const std::array<double, 3> num = scale(n2, n1 * w, n0 * w * w);
    for (int i = 0; i < 3; ++i) {
      f.b[static_cast<std::size_t>(i)] = num[static_cast<std::size_t>(i)] / den[0];
      f.a[static_cast<std::size_t>(i)] = den[static_cast<std::size_t>(i)] / den[0];
    }
    return f;
  }
  double step(double x) {
    const double y = b[0] * x + b[1] * x1 + b[2] * x2 - a[1] * y1 - a[2] * y2;
    x2 = x1;
    x1 = x;
    y2 = y1;
    y1 = y;
    return y;
  }
};

// The window's parameters recomputed from the samples, the candidate's first sample given.
TEST(PWaveStage, EarlyParametersMatchAnIndependentComputation) {
  SyntheticQuake quake;
  quake.s_after_p_s = 2.5;
  for (const double rate : {200.0, 1000.0}) {
    quake.rate_hz = rate;
    PWaveStage stage = make(with_fragility(rate, 0.5, 0.4));
    const std::vector<Vector3r> samples = quake.samples();
    const Trace trace = run(stage, samples);
    const PWaveStatus& end = trace.status.back();
    ASSERT_EQ(end.triggers, 1U);
    const PWaveSettings& p = stage.settings();
    const double t = p.sample_period_s;
    const auto first = static_cast<std::size_t>(std::llround(end.onset_s / t));
    const std::size_t last = first + static_cast<std::size_t>(std::llround(end.window_s / t));
    // a: the band-pass over the whole stream, per axis; v and d: from rest at the onset.
    std::array<Biquad, 3> low, high;
    for (auto& f : low) f = Biquad::bilinear(0.0, 0.0, 1.0, p.lowpass_hz, t);
    for (auto& f : high) f = Biquad::bilinear(1.0, 0.0, 0.0, p.highpass_hz, t);
    // HP(s) / s = s / (s^2 + sqrt2 w s + w^2): n1 w = 1.
    const double w = 2.0 / t * std::tan(kPi * p.highpass_hz * t);
    Biquad velocity = Biquad::bilinear(0.0, 1.0 / w, 0.0, p.highpass_hz, t);
    Biquad displacement = velocity;
    double pa = 0, pv = 0, pd = 0, ph = 0, sum_a2 = 0, sum_v2 = 0, sum_d2 = 0;
    for (std::size_t i = 0; i <= last; ++i) {
      std::array<double, 3> a{};
      for (std::size_t k = 0; k < 3; ++k) a[k] = high[k].step(low[k].step(samples[i][static_cast<Eigen::Index>(k)]));
      if (i < first) continue;
      const double v = velocity.step(a[2]);
      const double d = displacement.step(v);
      pa = std::max(pa, std::fabs(a[2]));
      pv = std::max(pv, std::fabs(v));
      pd = std::max(pd, std::fabs(d));
      ph = std::max(ph, std::hypot(a[0], a[1]));
      sum_a2 += a[2] * a[2];
      sum_v2 += v * v;
      sum_d2 += d * d;
    }
    SCOPED_TRACE(std::to_string(rate) + " Hz");
    EXPECT_EQ(end.window_end, PWaveWindowEnd::kSWave);
    EXPECT_NEAR(end.pa_m_s2, pa, 1e-9 * pa);
    EXPECT_NEAR(end.pv_m_s, pv, 1e-9 * pv);
    EXPECT_NEAR(end.pd_m, pd, 1e-9 * pd);
    EXPECT_NEAR(end.horizontal_m_s2, ph, 1e-9 * ph);
    EXPECT_NEAR(end.tau_c_s, 2.0 * kPi * std::sqrt(sum_d2 / sum_v2), 1e-9);
    EXPECT_NEAR(end.tau_p_s, 2.0 * kPi * std::sqrt(sum_v2 / sum_a2), 1e-9);
    // The S waves closed it: peak |a_h| reached s_wave_ratio times Pa on its last sample.
    EXPECT_GE(ph, p.s_wave_ratio * pa);
    // The prediction and the probability are the table's and the fragility's closed forms.
    const PWavePredictorPoint q = stage.predictor_at(end.window_s);
    const double ln_pga = std::log(pa) + q.ln_pga_over_pa + q.tau_c_exponent * std::log(end.tau_c_s);
    EXPECT_NEAR(end.predicted_pga_g, std::exp(ln_pga) / kGravity, 1e-9 * end.predicted_pga_g);
    EXPECT_DOUBLE_EQ(end.sigma_ln, q.sigma_ln);
    // The event's highest probability, held at the close: at least the last one's.
    const PWaveStatus& closed = trace.status[last];
    EXPECT_EQ(closed.state, PWaveState::kHolding);
    EXPECT_GE(closed.probability, stage.collapse_probability(end.predicted_pga_g, end.sigma_ln));
    EXPECT_GT(closed.probability, 0.0);
  }
}

TEST(PWaveStage, ProbabilityIsTheFragilityUnderThePredictionsScatter) {
  PWaveStage stage = make(with_fragility(200.0, 0.4, 0.3));
  // At the median, half; one total sigma above, Phi(1).
  EXPECT_DOUBLE_EQ(stage.collapse_probability(0.4, 0.4), 0.5);
  const double total = std::sqrt(0.3 * 0.3 + 0.4 * 0.4);  // 0.5
  EXPECT_NEAR(stage.collapse_probability(0.4 * std::exp(total), 0.4), 0.8413447460685429, 1e-12);
  EXPECT_NEAR(stage.collapse_probability(0.4 * std::exp(-2.0 * total), 0.4), 0.02275013194817922,
              1e-12);
  // The same numbers as the stage's own convolution had before it called the fragility's: the
  // curve with beta and sigma_ln added in quadrature, to the last bit.
  for (const double pga : {0.01, 0.1, 0.3, 0.4, 0.7, 1.5, 4.0}) {
    for (const double sigma : {0.0, 0.2, 0.65, 1.02}) {
      const LognormalFragility widened{0.4, std::sqrt(0.3 * 0.3 + sigma * sigma)};
      EXPECT_EQ(stage.collapse_probability(pga, sigma), widened.probability(pga))
          << pga << " " << sigma;
    }
  }
  // No fragility: no probability.
  PWaveStage unknown = make(at_rate(200.0));
  EXPECT_EQ(unknown.collapse_probability(10.0, 0.4), 0.0);
}

TEST(PWaveStage, PredictorIsInterpolatedInTheWindowAndHeldBeyondItsEnds) {
  PWaveSettings s = at_rate(200.0);
  s.predictor_points = 3;
  s.predictor[0] = {1.0, 3.0, 0.5, 0.6};
  s.predictor[1] = {2.0, 4.0, 0.0, 0.8};
  s.predictor[2] = {4.0, 2.0, 1.0, 1.0};
  PWaveStage stage = make(s);
  EXPECT_DOUBLE_EQ(stage.predictor_at(0.5).ln_pga_over_pa, 3.0);
  EXPECT_DOUBLE_EQ(stage.predictor_at(1.5).ln_pga_over_pa, 3.5);
  EXPECT_DOUBLE_EQ(stage.predictor_at(1.5).tau_c_exponent, 0.25);
  EXPECT_DOUBLE_EQ(stage.predictor_at(3.0).sigma_ln, 0.9);
  EXPECT_DOUBLE_EQ(stage.predictor_at(9.0).ln_pga_over_pa, 2.0);
  // ln PGA = ln Pa + c0 + c1 ln tau_c.
  EXPECT_NEAR(stage.predicted_ln_pga(0.2, 2.0, 3.0), std::log(0.2) + 3.0 + 0.5 * std::log(2.0),
              1e-12);
}

TEST(PWaveStage, ProbabilityIsHeldThenTheStageRearms) {
  SyntheticQuake quake;
  quake.s_after_p_s = 2.0;
  quake.seconds = 70.0;
  PWaveSettings s = with_fragility(quake.rate_hz, 0.2, 0.3);
  s.hold_s = 10.0;
  PWaveStage stage = make(s);
  const Trace trace = run(stage, quake.samples());
  const PWaveStatus& last = trace.status.back();
  ASSERT_EQ(last.triggers, 1U);
  const double closed_at = last.onset_s + last.window_s;
  const PWaveStatus& held = trace.at(closed_at + 5.0, quake.rate_hz);
  EXPECT_EQ(held.state, PWaveState::kHolding);
  EXPECT_GT(held.probability, 0.0);
  // The highest probability of the event is the one held.
  EXPECT_EQ(held.probability, highest_probability(trace));
  // After hold_s: idle, probability 0, and the S waves' coda (the LTA followed it while
  // holding) does not trigger again.
  const PWaveStatus& after = trace.at(closed_at + 10.5, quake.rate_hz);
  EXPECT_EQ(after.state, PWaveState::kIdle);
  EXPECT_EQ(after.probability, 0.0);
  EXPECT_EQ(last.triggers, 1U);
}

TEST(PWaveStage, APWaveTooSmallDoesNotStartACandidate) {
  SyntheticQuake quake;
  quake.noise_m_s2 = 0.0005;
  quake.p_amplitude_m_s2 = 0.03;  // rms about 0.02, below min_amplitude_m_s2 (0.05)
  quake.s_after_p_s = -1.0;
  PWaveStage stage = make(at_rate(quake.rate_hz));
  const Trace trace = run(stage, quake.samples());
  EXPECT_EQ(trace.status.back().candidates, 0U);
  // Its STA / LTA passed the ratio (before the LTA, not frozen while idle, caught up).
  EXPECT_GT(trace.at(quake.p_at_s + 0.6, quake.rate_hz).sta_lta, stage.settings().trigger_ratio);
}

TEST(PWaveStage, RejectsShortPeriodsAndHorizontalMotion) {
  {
    SyntheticQuake quake;  // a 12 Hz "P wave": a building's vibration, not an earthquake's
    quake.p_hz = 12.0;
    quake.p_amplitude_m_s2 = 5.0;
    quake.s_after_p_s = -1.0;
    PWaveStage stage = make(at_rate(quake.rate_hz));
    const Trace trace = run(stage, quake.samples());
    const PWaveStatus& end = trace.status.back();
    EXPECT_EQ(end.triggers, 0U);
    EXPECT_GT(end.rejected_short, 0U);
    EXPECT_EQ(trace.at(quake.p_at_s + 0.9, quake.rate_hz).last_rejection,
              PWaveRejection::kPeriodShort);
    // It goes on: after max_retry_s its excitation is refused, not retried for 40 s.
    EXPECT_EQ(end.rejected_not_after_quiet, 1U);
    EXPECT_EQ(end.last_rejection, PWaveRejection::kNotAfterQuiet);
  }
  {
    SyntheticQuake quake;  // S waves without a P wave: a record that begins in the S waves
    quake.p_amplitude_m_s2 = 0.0;
    quake.s_after_p_s = 0.0;
    quake.s_amplitude_m_s2 = 1.5;
    std::vector<Vector3r> samples = quake.samples();
    // Its S waves carry some vertical motion, a fifth of their horizontal.
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double t = static_cast<double>(i) / quake.rate_hz - quake.p_at_s;
      if (t > 0) samples[i].z() += 0.3 * std::sin(2.0 * kPi * 0.9 * t);
    }
    PWaveStage stage = make(at_rate(quake.rate_hz));
    const PWaveStatus end = run(stage, samples).status.back();
    EXPECT_EQ(end.triggers, 0U);
    EXPECT_GT(end.rejected_horizontal, 0U);
  }
}

// A record that begins in the strong motion (docs/pwave.md: held-out records on which the stage
// triggered seconds into their S waves): after 20 s of quiet, horizontal shaking of 1.5 m/s2
// at once, its vertical part growing from a seventh of it to its equal over 8 s. Each 0.5 s
// candidate is rejected as not vertical enough and retried at once (the STA stays 8 times the
// pre-event LTA, frozen while a candidate runs) until, 3 s in, one passes every test of a P wave.
std::vector<Vector3r> begins_in_the_s_waves(double rate_hz) {
  SyntheticQuake quiet;
  quiet.rate_hz = rate_hz;
  quiet.p_amplitude_m_s2 = 0.0;
  quiet.s_after_p_s = -1.0;
  std::vector<Vector3r> samples = quiet.samples();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double t = static_cast<double>(i) / rate_hz - quiet.p_at_s;
    if (t < 0.0) continue;
    samples[i].x() += 1.5 * std::sin(2.0 * kPi * 1.2 * t);
    samples[i].z() += (0.2 + 1.3 * std::min(1.0, t / 8.0)) * std::sin(2.0 * kPi * 0.9 * t);
  }
  return samples;
}

TEST(PWaveStage, ARecordThatBeginsInTheSWavesDoesNotTrigger) {
  for (const double rate : {200.0, 1000.0}) {
    SCOPED_TRACE(std::to_string(rate) + " Hz");
    const std::vector<Vector3r> samples = begins_in_the_s_waves(rate);
    PWaveStage stage = make(with_fragility(rate, 0.2, 0.3));
    const Trace trace = run(stage, samples);
    const PWaveStatus& end = trace.status.back();
    EXPECT_EQ(end.triggers, 0U);
    EXPECT_EQ(highest_probability(trace), 0.0);
    // The first candidate and its retries within max_retry_s (2 s: at 0, 0.5, 1 and 1.5 s),
    // then the excitation is refused, counted once.
    EXPECT_EQ(end.candidates, 4U);
    EXPECT_EQ(end.rejected_horizontal, 4U);
    EXPECT_EQ(end.rejected_not_after_quiet, 1U);
    EXPECT_EQ(trace.at(20.0 + 2.5, rate).last_rejection, PWaveRejection::kNotAfterQuiet);
    EXPECT_EQ(trace.at(20.0 + 2.5, rate).state, PWaveState::kIdle);
    // Without the guard (retries for a minute) a retry 3 s into the shaking triggers: the S
    // waves read as a P wave, and the probability follows.
    PWaveSettings unguarded = with_fragility(rate, 0.2, 0.3);
    unguarded.max_retry_s = 60.0;
    PWaveStage retrying = make(unguarded);
    const Trace late = run(retrying, samples);
    EXPECT_EQ(late.status.back().triggers, 1U);
    EXPECT_GT(late.status.back().onset_s, 20.0 + 2.0);
    EXPECT_GT(highest_probability(late), 0.9);
  }
}

// The guard changes nothing on a P wave after quiet: the same status at every sample as a
// stage that retries for a minute, also where the onset's first candidates are rejected (a P
// wave whose first 0.5 or 1.2 s carry a horizontal part of 1 m/s2, three times its vertical
// one) and a retry triggers within max_retry_s.
TEST(PWaveStage, APWaveAfterQuietTriggersAsWithoutTheGuard) {
  for (const double horizontal_s : {0.0, 0.5, 1.2}) {
    SCOPED_TRACE("horizontal onset " + std::to_string(horizontal_s) + " s");
    SyntheticQuake quake;
    quake.s_after_p_s = -1.0;
    std::vector<Vector3r> samples = quake.samples();
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double t = static_cast<double>(i) / quake.rate_hz - quake.p_at_s;
      if (t >= 0.0 && t < horizontal_s) samples[i].x() += std::sin(2.0 * kPi * 0.7 * t);
    }
    PWaveStage guarded = make(with_fragility(quake.rate_hz, 0.5, 0.4));
    PWaveSettings unguarded = with_fragility(quake.rate_hz, 0.5, 0.4);
    unguarded.max_retry_s = 60.0;
    PWaveStage retrying = make(unguarded);
    const Trace a = run(guarded, samples);
    const Trace b = run(retrying, samples);
    const PWaveStatus& end = a.status.back();
    ASSERT_EQ(end.triggers, 1U);
    const std::uint64_t rejected = horizontal_s == 0.0 ? 0U : horizontal_s < 1.0 ? 1U : 2U;
    EXPECT_EQ(end.candidates, rejected + 1U);
    EXPECT_EQ(end.rejected_horizontal, rejected);
    EXPECT_EQ(end.rejected_not_after_quiet, 0U);
    EXPECT_GE(end.onset_s, quake.p_at_s + 0.5 * static_cast<double>(rejected));
    EXPECT_LE(end.onset_s, quake.p_at_s + 0.5 * static_cast<double>(rejected) + 0.3);
    for (std::size_t i = 0; i < a.status.size(); ++i) {
      ASSERT_EQ(a.status[i].state, b.status[i].state) << i;
      ASSERT_EQ(a.status[i].probability, b.status[i].probability) << i;
      ASSERT_EQ(a.status[i].onset_s, b.status[i].onset_s) << i;
    }
  }
}

TEST(PWaveStage, HorizontalChannelTriggersOnTheHorizontalPair) {
  SyntheticQuake quake;
  quake.s_after_p_s = -1.0;
  std::vector<Vector3r> samples = quake.samples();
  for (Vector3r& a : samples) std::swap(a.y(), a.z());  // the P wave on y, nothing vertical
  PWaveSettings s = at_rate(quake.rate_hz);
  PWaveStage vertical = make(s);
  EXPECT_EQ(run(vertical, samples).status.back().triggers, 0U);
  s.channel = PWaveChannel::kHorizontal;
  PWaveStage horizontal = make(s);
  const PWaveStatus end = run(horizontal, samples).status.back();
  EXPECT_EQ(end.triggers, 1U);
  EXPECT_EQ(end.window_end, PWaveWindowEnd::kMaxWindow);  // no S-wave test on this channel
}

TEST(PWaveStage, RefusesNonFiniteSamplesAndRestartsClean) {
  SyntheticQuake quake;
  quake.s_after_p_s = -1.0;
  PWaveStage stage = make(at_rate(quake.rate_hz));
  const std::vector<Vector3r> samples = quake.samples();
  for (std::size_t i = 0; i < samples.size() / 2; ++i) (void)stage.update(samples[i]);
  const PWaveStatus before = stage.status();
  (void)stage.update(Vector3r(0.0, std::numeric_limits<double>::quiet_NaN(), 0.0));
  EXPECT_EQ(stage.refused(), 1U);
  EXPECT_EQ(stage.status().sta_lta, before.sta_lta);
  ASSERT_EQ(before.triggers, 1U);
  stage.restart();
  EXPECT_EQ(stage.status().state, PWaveState::kIdle);
  EXPECT_EQ(stage.status().probability, 0.0);
  EXPECT_EQ(stage.status().triggers, 1U);  // counters are kept
  EXPECT_EQ(stage.status().sta_lta, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Non-earthquake signals (nuisance_signals.h): no trigger over the models' ranges, at the
// box's lowest and highest rates, after 20 s of quiet (1 mg of sensor noise).

void expect_no_trigger(const testing::Motion& motion, const std::string& what) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  PWaveStage stage = make(with_fragility(motion.rate_hz, 0.2, 0.3));
  const auto quiet = static_cast<std::size_t>(20.0 * motion.rate_hz);
  for (std::size_t i = 0; i < quiet; ++i) (void)stage.update(Vector3r(noise(rng), noise(rng), noise(rng)));
  double highest_ratio = 0.0;
  for (const Eigen::Vector3d& a : motion.acceleration_m_s2()) {
    const Vector3r sample = a + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    highest_ratio = std::max(highest_ratio, double(stage.update(sample).sta_lta));
  }
  const PWaveStatus& s = stage.status();
  EXPECT_EQ(s.triggers, 0U) << what << ": tau_p " << s.tau_p_s << " s, tau_c " << s.tau_c_s
                            << " s, Pa " << s.pa_m_s2
                            << " m/s2, horizontal " << s.horizontal_m_s2;
  EXPECT_EQ(s.probability, 0.0) << what;
  ::testing::Test::RecordProperty(what, "candidates " + std::to_string(s.candidates) + ", highest STA/LTA " +
                           std::to_string(highest_ratio));
}

TEST(PWaveNuisance, FootstepsDoNotTrigger) {
  for (const double rate : {200.0, 1000.0}) {
    for (const double step_hz : {1.6, 2.0, 2.4}) {
      for (const double floor_hz : {5.0, 8.0, 12.0, 20.0}) {
        for (const double peak_g : {0.005, 0.015}) {  // DG11's limits: offices, malls
          testing::FootstepModel m;
          m.step_hz = step_hz;
          m.floor_hz = floor_hz;
          m.peak_g = peak_g;
          for (const unsigned seed : {1U, 2U}) {
            m.seed = seed;
            expect_no_trigger(testing::footsteps(m, rate),
                              "footsteps " + std::to_string(step_hz) + " Hz on a " +
                                  std::to_string(floor_hz) + " Hz floor, " +
                                  std::to_string(peak_g) + " g, seed " + std::to_string(seed) +
                                  ", " + std::to_string(rate) + " Hz");
          }
        }
      }
    }
  }
}

TEST(PWaveNuisance, DoorsDoNotTrigger) {
  for (const double rate : {200.0, 1000.0}) {
    for (const double mode_hz : {15.0, 25.0, 40.0}) {
      for (const double peak_g : {0.03, 0.2}) {
        testing::BurstModel m;
        m.mode_hz = mode_hz;
        m.peak_g = peak_g;
        expect_no_trigger(testing::door(m, rate), "door " + std::to_string(mode_hz) + " Hz, " +
                                                      std::to_string(peak_g) + " g");
      }
    }
  }
}

TEST(PWaveNuisance, TrafficDoesNotTrigger) {
  for (const double rate : {200.0, 1000.0}) {
    for (const auto& [low, high] : {std::pair{3.0, 10.0}, {5.0, 20.0}, {10.0, 30.0}}) {
      for (const double peak_g : {0.005, 0.02}) {  // 0.05 g: docs/pwave.md
        for (const unsigned seed : {1U, 2U}) {
          testing::TrafficModel m;
          m.low_hz = low;
          m.high_hz = high;
          m.peak_g = peak_g;
          m.seed = seed;
          expect_no_trigger(testing::traffic(m, rate),
                            "traffic " + std::to_string(low) + "-" + std::to_string(high) +
                                " Hz, " + std::to_string(peak_g) + " g, seed " +
                                std::to_string(seed));
        }
      }
    }
  }
}

TEST(PWaveNuisance, BumpsOfThePlinthDoNotTrigger) {
  for (const double rate : {200.0, 1000.0}) {
    for (const double mode_hz : {10.0, 20.0, 40.0}) {
      for (const double peak_g : {0.1, 0.3, 1.0}) {
        testing::BurstModel m;
        m.mode_hz = mode_hz;
        m.zeta = 0.08;
        m.peak_g = peak_g;
        expect_no_trigger(testing::bump(m, rate), "bump " + std::to_string(mode_hz) + " Hz, " +
                                                      std::to_string(peak_g) + " g");
      }
    }
  }
}

}  // namespace
}  // namespace plinth::monitor
