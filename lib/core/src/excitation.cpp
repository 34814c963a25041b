#include "plinth/core/excitation.h"

#include <cmath>
#include <numbers>

#include "plinth/core/internal/flows.h"

namespace plinth {

GroundAcceleration Excitation::pulse_at(Time t) const {
  if (t < 0.0 || t > period) return {};
  const auto phase = static_cast<Real>(2.0 * std::numbers::pi * t / period);
  const bool sine = kind == ExcitationKind::kSinePulse;
  if constexpr (real_tolerance::kSingle) {  // phase in [0, 2 pi]: bounded_trig.h
    const internal::SinCos trig = internal::real_sin_cos(phase);
    return {amplitude * (sine ? trig.sin : trig.cos), Real(0)};
  } else {
    return {amplitude * (sine ? std::sin(phase) : std::cos(phase)), Real(0)};
  }
}

Time Excitation::duration() const {
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

Excitation Excitation::record(SampledSignal h, SampledSignal v, Real gamma) {
  Excitation e;
  e.kind = ExcitationKind::kRecord;
  e.horizontal = h;
  e.vertical = v;
  e.scale = gamma;
  return e;
}

Excitation Excitation::sine_pulse(Real amplitude, Time period) {
  Excitation e;
  e.kind = ExcitationKind::kSinePulse;
  e.amplitude = amplitude;
  e.period = period;
  return e;
}

Excitation Excitation::cosine_pulse(Real amplitude, Time period) {
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
