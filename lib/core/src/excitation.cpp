#include "plinth/core/excitation.h"

#include <cmath>
#include <numbers>

namespace plinth {

GroundAcceleration Excitation::pulse_at(double t) const {
  if (t < 0.0 || t > period) return {};
  const double phase = 2.0 * std::numbers::pi * t / period;
  return {amplitude * (kind == ExcitationKind::kSinePulse ? std::sin(phase) : std::cos(phase)),
          0.0};
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
