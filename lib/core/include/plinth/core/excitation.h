// Ground motion that drives the base: a sampled record, a one-sine or one-cosine pulse, or none.
// An impulse is not a ground acceleration history but an initial condition (Eq 34); see
// Simulator::start_with_impulse.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace plinth {

struct GroundAcceleration {
  double horizontal = 0.0;  // u_G'', m/s2
  double vertical = 0.0;    // v_G'', m/s2 (positive up)
};

// A non-owning view of uniformly sampled values, m/s2, the first at t = 0.
struct SampledSignal {
  const double* values = nullptr;
  std::size_t count = 0;
  double dt = 0.0;  // s

  [[nodiscard]] bool empty() const { return count == 0; }
  // Linear interpolation between samples; zero before t = 0 and after the last sample.
  // Inline: the solver calls it at every Runge-Kutta stage.
  [[nodiscard]] double at(double t) const {
    if (count == 0 || t < 0.0) return 0.0;
    const double position = t / dt;
    const auto last = static_cast<double>(count - 1);
    if (position >= last) return position == last ? values[count - 1] : 0.0;
    // position >= 0: truncation is the floor (std::floor is a libm call without SSE4.1)
    const auto i = static_cast<std::size_t>(position);
    const double w = position - static_cast<double>(i);
    return values[i] + w * (values[i + 1] - values[i]);
  }
  [[nodiscard]] double duration() const {
    return count == 0 ? 0.0 : static_cast<double>(count - 1) * dt;
  }
};

// Ground motion arriving sample by sample (the monitor): the two newest samples, linearly
// interpolated between them, held at the newer one past it. The owner advances it one sample at
// a time; an Excitation refers to it and must not outlive it.
struct GroundStream {
  double start_time = 0.0;  // s, time of `previous`
  double period = 1.0;      // s, between the two samples
  GroundAcceleration previous;
  GroundAcceleration latest;
  std::int64_t latest_index = 0;  // `latest` is sample n, at t = n period

  [[nodiscard]] GroundAcceleration at(double t) const {
    double w = (t - start_time) / period;
    w = w < 0.0 ? 0.0 : (w > 1.0 ? 1.0 : w);
    return {previous.horizontal + w * (latest.horizontal - previous.horizontal),
            previous.vertical + w * (latest.vertical - previous.vertical)};
  }
  // The next sample arrives: the interval moves on by one period.
  void push(GroundAcceleration sample) {
    start_time = static_cast<double>(latest_index) * period;  // no drift over hours
    ++latest_index;
    previous = latest;
    latest = sample;
  }
  // Sample 0 at t = 0: held until the next one arrives.
  void reset(double sample_period, GroundAcceleration first) {
    period = sample_period;
    start_time = -sample_period;
    latest_index = 0;
    previous = first;
    latest = first;
  }
};

enum class ExcitationKind : unsigned char { kNone, kRecord, kSinePulse, kCosinePulse, kStream };

struct Excitation {
  ExcitationKind kind = ExcitationKind::kNone;
  SampledSignal horizontal;  // kRecord only
  SampledSignal vertical;    // kRecord only; empty: no vertical motion
  double scale = 1.0;        // gamma: multiplies the record (Section 4.2)
  double amplitude = 0.0;    // pulses: peak ground acceleration, m/s2
  double period = 0.0;       // pulses: duration of the single period, s
  const GroundStream* stream = nullptr;  // kStream only

  [[nodiscard]] GroundAcceleration pulse_at(double t) const;

  // Inline for what the solver meets at every Runge-Kutta stage (none, a record, the stream);
  // the pulses' sine out of line.
  [[nodiscard, gnu::always_inline]] GroundAcceleration at(double t) const {
    if (kind == ExcitationKind::kNone) return {};
    if (kind == ExcitationKind::kRecord) {
      return {scale * horizontal.at(t), vertical.empty() ? 0.0 : scale * vertical.at(t)};
    }
    if (kind == ExcitationKind::kStream) return stream->at(t);
    return pulse_at(t);
  }
  // Time after which the ground is still, s.
  [[nodiscard]] double duration() const;

  [[nodiscard]] static Excitation none() { return {}; }
  [[nodiscard]] static Excitation record(SampledSignal h, SampledSignal v = {}, double gamma = 1.0);
  // One period of A sin(2 pi t / Tp) (or A cos(...)), zero outside [0, Tp].
  [[nodiscard]] static Excitation sine_pulse(double amplitude, double period);
  [[nodiscard]] static Excitation cosine_pulse(double amplitude, double period);
  // Samples as they arrive; `stream` must outlive the excitation and its copies.
  [[nodiscard]] static Excitation streamed(const GroundStream& stream);
};

}  // namespace plinth
