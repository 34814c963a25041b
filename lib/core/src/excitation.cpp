#include "plinth/core/excitation.h"

#include <cmath>
#include <numbers>

namespace plinth {

double SampledSignal::at(double t) const {
  if (count == 0 || t < 0.0) return 0.0;
  const double position = t / dt;
  const auto last = static_cast<double>(count - 1);
  if (position >= last) return position == last ? values[count - 1] : 0.0;
  const double floor_position = std::floor(position);
  const auto i = static_cast<std::size_t>(floor_position);
  const double w = position - floor_position;
  return values[i] + w * (values[i + 1] - values[i]);
}

GroundAcceleration Excitation::at(double t) const {
  switch (kind) {
    case ExcitationKind::kNone:
      return {};
    case ExcitationKind::kRecord:
      return {scale * horizontal.at(t), scale * vertical.at(t)};
    case ExcitationKind::kSinePulse:
      if (t < 0.0 || t > period) return {};
      return {amplitude * std::sin(2.0 * std::numbers::pi * t / period), 0.0};
    case ExcitationKind::kCosinePulse:
      if (t < 0.0 || t > period) return {};
      return {amplitude * std::cos(2.0 * std::numbers::pi * t / period), 0.0};
    case ExcitationKind::kStream:
      return stream->at(t);
  }
  return {};
}

double Excitation::duration() const {
  switch (kind) {
    case ExcitationKind::kNone:
      return 0.0;
    case ExcitationKind::kRecord:
      return horizontal.duration() > vertical.duration() ? horizontal.duration()
                                                         : vertical.duration();
    case ExcitationKind::kSinePulse:
    case ExcitationKind::kCosinePulse:
      return period;
    case ExcitationKind::kStream:  // as far as samples have arrived
      return stream->start_time + stream->period;
  }
  return 0.0;
}

Excitation Excitation::record(SampledSignal h, SampledSignal v, double gamma) {
  Excitation e;
  e.kind = ExcitationKind::kRecord;
  e.horizontal = h;
  e.vertical = v;
  e.scale = gamma;
  return e;
}

Excitation Excitation::sine_pulse(double amplitude, double period) {
  Excitation e;
  e.kind = ExcitationKind::kSinePulse;
  e.amplitude = amplitude;
  e.period = period;
  return e;
}

Excitation Excitation::cosine_pulse(double amplitude, double period) {
  Excitation e;
  e.kind = ExcitationKind::kCosinePulse;
  e.amplitude = amplitude;
  e.period = period;
  return e;
}

Excitation Excitation::streamed(const GroundStream& stream) {
  Excitation e;
  e.kind = ExcitationKind::kStream;
  e.stream = &stream;
  return e;
}

}  // namespace plinth
