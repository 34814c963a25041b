// Ground motion that drives the base: a sampled record, a one-sine or one-cosine pulse, or none.
// An impulse is not a ground acceleration history but an initial condition (Eq 34); see
// Simulator::start_with_impulse.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "plinth/core/real.h"

namespace plinth {

struct GroundAcceleration {
  Real horizontal = 0.0;  // u_G'', m/s2
  Real vertical = 0.0;    // v_G'', m/s2 (positive up)
};

// A non-owning view of uniformly sampled values, m/s2, the first at t = 0. The values and their
// times are double (a host's record, read from a file) whatever Real is; at() gives a Real.
struct SampledSignal {
  const double* values = nullptr;
  std::size_t count = 0;
  Time dt = 0.0;  // s

  [[nodiscard]] bool empty() const { return count == 0; }
  // Linear interpolation between samples; zero before t = 0 and after the last sample.
  // Inline: the solver calls it at every Runge-Kutta stage.
  [[nodiscard]] Real at(Time t) const {
    if (count == 0 || t < 0.0) return 0;
    const double position = t / dt;
    const auto last = static_cast<double>(count - 1);
    if (position >= last) return position == last ? static_cast<Real>(values[count - 1]) : 0;
    // position >= 0: truncation is the floor (std::floor is a libm call without SSE4.1)
    const auto i = static_cast<std::size_t>(position);
    // The weight and the samples in Real (in a double build the same expression as in double).
    const auto w = static_cast<Real>(position - static_cast<double>(i));
    const auto v0 = static_cast<Real>(values[i]);
    return v0 + w * (static_cast<Real>(values[i + 1]) - v0);
  }
  [[nodiscard]] Time duration() const {
    return count == 0 ? 0.0 : static_cast<Time>(count - 1) * dt;
  }
};

// Ground motion arriving sample by sample (the monitor): the two newest samples, linearly
// interpolated between them, held at the newer one past it. The owner advances it one sample at
// a time; an Excitation refers to it and must not outlive it.
struct GroundStream {
  Time start_time = 0.0;  // s, time of `previous`
  Time period = 1.0;      // s, between the two samples
  Real period_real = 1.0;  // s, `period` in Real (set with it by reset)
  GroundAcceleration previous;
  GroundAcceleration latest;
  std::int64_t latest_index = 0;  // `latest` is sample n, at t = n period

  [[nodiscard]] GroundAcceleration at(Time t) const {
    // The offset into the interval in Time (t is far from 0 after hours), then the fraction in
    // Real: the offset is under a few periods, which Real resolves (in a double build the same
    // expression as in double).
    const Real w = weight(static_cast<Real>(t - start_time) / period_real);
    return {previous.horizontal + w * (latest.horizontal - previous.horizontal),
            previous.vertical + w * (latest.vertical - previous.vertical)};
  }
  // The interpolation weight of a fraction of the interval, held at the samples beyond it.
  [[nodiscard]] static Real weight(Real fraction) {
    return fraction < Real(0) ? Real(0) : (fraction > Real(1) ? Real(1) : fraction);
  }
  // The next sample arrives: the interval moves on by one period.
  void push(GroundAcceleration sample) {
    start_time = static_cast<Time>(latest_index) * period;  // no drift over hours
    ++latest_index;
    previous = latest;
    latest = sample;
  }
  // Sample 0 at t = 0: held until the next one arrives.
  void reset(Time sample_period, GroundAcceleration first) {
    period = sample_period;
    period_real = static_cast<Real>(sample_period);
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
  Real scale = 1.0;          // gamma: multiplies the record (Section 4.2)
  Real amplitude = 0.0;      // pulses: peak ground acceleration, m/s2
  Time period = 0.0;         // pulses: duration of the single period, s
  const GroundStream* stream = nullptr;  // kStream only

  [[nodiscard]] GroundAcceleration pulse_at(Time t) const;

  // Inline for what the solver meets at every Runge-Kutta stage (none, a record, the stream);
  // the pulses' sine out of line.
  [[nodiscard, gnu::always_inline]] GroundAcceleration at(Time t) const {
    if (kind == ExcitationKind::kNone) return {};
    if (kind == ExcitationKind::kRecord) {
      return {scale * horizontal.at(t), vertical.empty() ? Real(0) : scale * vertical.at(t)};
    }
    if (kind == ExcitationKind::kStream) return stream->at(t);
    return pulse_at(t);
  }
  // Time after which the ground is still, s.
  [[nodiscard]] Time duration() const;

  [[nodiscard]] static Excitation none() { return {}; }
  [[nodiscard]] static Excitation record(SampledSignal h, SampledSignal v = {},
                                         Real gamma = Real(1));
  // One period of A sin(2 pi t / Tp) (or A cos(...)), zero outside [0, Tp].
  [[nodiscard]] static Excitation sine_pulse(Real amplitude, Time period);
  [[nodiscard]] static Excitation cosine_pulse(Real amplitude, Time period);
  // Samples as they arrive; `stream` must outlive the excitation and its copies.
  [[nodiscard]] static Excitation streamed(const GroundStream& stream);
};

}  // namespace plinth
