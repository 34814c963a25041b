// Ground motion that drives the base: a sampled record, a one-sine or one-cosine pulse, or none.
// An impulse is not a ground acceleration history but an initial condition (Eq 34); see
// Simulator::start_with_impulse.
#pragma once

#include <cstddef>

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
  [[nodiscard]] double at(double t) const;
  [[nodiscard]] double duration() const {
    return count == 0 ? 0.0 : static_cast<double>(count - 1) * dt;
  }
};

enum class ExcitationKind : unsigned char { kNone, kRecord, kSinePulse, kCosinePulse };

struct Excitation {
  ExcitationKind kind = ExcitationKind::kNone;
  SampledSignal horizontal;  // kRecord only
  SampledSignal vertical;    // kRecord only; empty: no vertical motion
  double scale = 1.0;        // gamma: multiplies the record (Section 4.2)
  double amplitude = 0.0;    // pulses: peak ground acceleration, m/s2
  double period = 0.0;       // pulses: duration of the single period, s

  [[nodiscard]] GroundAcceleration at(double t) const;
  // Time after which the ground is still, s.
  [[nodiscard]] double duration() const;

  [[nodiscard]] static Excitation none() { return {}; }
  [[nodiscard]] static Excitation record(SampledSignal h, SampledSignal v = {}, double gamma = 1.0);
  // One period of A sin(2 pi t / Tp) (or A cos(...)), zero outside [0, Tp].
  [[nodiscard]] static Excitation sine_pulse(double amplitude, double period);
  [[nodiscard]] static Excitation cosine_pulse(double amplitude, double period);
};

}  // namespace plinth
