#pragma once
// Synthesised ground motions that are not earthquakes, as the box's ground sensor beside a
// plinth would see them (docs/pwave.md, "Non-earthquake signals"). No recordings with a clear
// licence were found; these are models, each with its source.
//
// Every vibration is defined by its displacement and the sensor sees the second central
// difference of it at its sample rate: a floor, a door frame or a plinth moves and comes back
// to rest, so the motion's velocity and displacement return to zero as a real one's do (a
// damped sine written directly as an acceleration would carry a net velocity and a drifting
// displacement that no floor has). Each impact is a mode (frequency f, damping zeta) struck by
// a smooth force pulse sin^2(pi t / t_p), 0 <= t <= t_p, from rest: its displacement is the
// mode's equation u'' + 2 zeta w u' + w^2 u = p(t) integrated by RK4 at 1/20 of the sample
// period, scaled so that its acceleration peaks at the impact's amplitude.
//
//   footsteps  a walker passing the plinth at 1.3 m/s (closest at mid-record, the amplitude
//              falling as 1 / (1 + (d / 2 m)^2)); every step (f_step 1.6 to 2.4 Hz, 5 %
//              jitter, amplitude 0.8 to 1.2 of the walker's) is a heel strike of t_p = 0.1 s
//              on the floor's mode (4 to 20 Hz, zeta 3 %: AISC Design Guide 11), vertical
//              peak_g, horizontal 0.3 peak_g on a mode 1.3 times higher. DG11 limits walking
//              to 0.5 %g in offices and 1.5 %g in shopping malls; 5 %g is a footbridge's.
//   door       a slam and its latch 0.15 s later (t_p = 0.01 s): the frame's and wall's modes
//              (15 to 40 Hz, zeta 5 %), vertical peak_g, horizontal 0.7 peak_g.
//   traffic    a truck passing: band-passed Gaussian noise (2nd-order Butterworth band,
//              3-10, 5-20 or 10-30 Hz: soft soil to stiff), a Gaussian envelope of 8 s, the
//              three axes independent with the same peak_g (0.05 g is past the vibration that
//              damages buildings: 10 mm/s at 10 Hz is 0.06 g).
//   bump       someone knocks into the plinth (t_p = 0.02 s): its mode (10 to 40 Hz, zeta
//              8 %), horizontal peak_g, vertical 0.3 peak_g on a mode 1.5 times higher.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <random>
#include <vector>

#include "plinth/core/scene.h"

namespace plinth::testing {

struct Motion {
  double rate_hz = 200.0;
  std::vector<Eigen::Vector3d> displacement_m;  // x, y horizontal; z vertical

  // The sensor's samples: the second central difference (zero at the two ends).
  [[nodiscard]] std::vector<Eigen::Vector3d> acceleration_m_s2() const {
    std::vector<Eigen::Vector3d> a(displacement_m.size(), Eigen::Vector3d::Zero());
    for (std::size_t i = 1; i + 1 < displacement_m.size(); ++i) {
      a[i] = (displacement_m[i + 1] - 2.0 * displacement_m[i] + displacement_m[i - 1]) *
             rate_hz * rate_hz;
    }
    return a;
  }
};

inline Motion quiet(double seconds, double rate_hz) {
  Motion m;
  m.rate_hz = rate_hz;
  m.displacement_m.assign(static_cast<std::size_t>(seconds * rate_hz), Eigen::Vector3d::Zero());
  return m;
}

// A mode struck from rest (above): its displacement at the sample rate for an acceleration
// peak of 1 m/s2.
inline std::vector<double> impact(double f_hz, double zeta, double pulse_s, double rate_hz) {
  constexpr int kSubsteps = 20;
  const double w = 2.0 * std::numbers::pi * f_hz;
  const double seconds = std::min(6.0, 8.0 / (zeta * w));
  const double h = 1.0 / (rate_hz * kSubsteps);
  const auto force = [&](double t) {
    if (t > pulse_s) return 0.0;
    const double s = std::sin(std::numbers::pi * t / pulse_s);
    return s * s;
  };
  const auto rate = [&](double t, const Eigen::Vector2d& y) {
    return Eigen::Vector2d(y[1], force(t) - 2.0 * zeta * w * y[1] - w * w * y[0]);
  };
  std::vector<double> u;
  Eigen::Vector2d y = Eigen::Vector2d::Zero();
  const auto steps = static_cast<std::size_t>(seconds * rate_hz) * kSubsteps;
  for (std::size_t i = 0; i < steps; ++i) {
    if (i % kSubsteps == 0) u.push_back(y[0]);
    const double t = static_cast<double>(i) * h;
    const Eigen::Vector2d k1 = rate(t, y);
    const Eigen::Vector2d k2 = rate(t + 0.5 * h, y + 0.5 * h * k1);
    const Eigen::Vector2d k3 = rate(t + 0.5 * h, y + 0.5 * h * k2);
    const Eigen::Vector2d k4 = rate(t + h, y + h * k3);
    y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  double peak = 0.0;
  for (std::size_t i = 1; i + 1 < u.size(); ++i) {
    peak = std::max(peak, std::fabs(u[i + 1] - 2.0 * u[i] + u[i - 1]) * rate_hz * rate_hz);
  }
  for (double& v : u) v /= peak;
  return u;
}

// Adds `amplitude` times an impact to axis `axis` of the motion from time t0.
inline void add(Motion& m, int axis, const std::vector<double>& impact_m, double t0,
                double amplitude) {
  const auto first = static_cast<std::size_t>(std::llround(t0 * m.rate_hz));
  for (std::size_t i = 0; i < impact_m.size() && first + i < m.displacement_m.size(); ++i) {
    m.displacement_m[first + i][axis] += amplitude * impact_m[i];
  }
}

struct FootstepModel {
  double step_hz = 2.0;
  double floor_hz = 12.0;
  double zeta = 0.03;
  double peak_g = 0.015;
  double seconds = 30.0;
  unsigned seed = 1;
};

inline Motion footsteps(const FootstepModel& p, double rate_hz) {
  Motion m = quiet(p.seconds, rate_hz);
  std::mt19937_64 rng(p.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::vector<double> vertical = impact(p.floor_hz, p.zeta, 0.1, rate_hz);
  const std::vector<double> horizontal = impact(1.3 * p.floor_hz, p.zeta, 0.1, rate_hz);
  const double peak = p.peak_g * kStandardGravity;
  for (double t = 2.0; t < p.seconds - 1.0; t += (0.95 + 0.1 * unit(rng)) / p.step_hz) {
    const double d = 1.3 * (t - 0.5 * p.seconds) / 2.0;
    const double amplitude = peak / (1.0 + d * d) * (0.8 + 0.4 * unit(rng));
    add(m, 2, vertical, t, amplitude);
    add(m, 0, horizontal, t, (unit(rng) < 0.5 ? -0.3 : 0.3) * amplitude);
  }
  return m;
}

struct BurstModel {
  double mode_hz = 25.0;
  double zeta = 0.05;
  double peak_g = 0.03;
  double at_s = 3.0;
  double seconds = 10.0;
};

inline Motion door(const BurstModel& p, double rate_hz) {
  Motion m = quiet(p.seconds, rate_hz);
  const double peak = p.peak_g * kStandardGravity;
  const double latch = p.at_s + 0.15;
  add(m, 2, impact(p.mode_hz, p.zeta, 0.01, rate_hz), p.at_s, peak);
  add(m, 2, impact(1.2 * p.mode_hz, p.zeta, 0.01, rate_hz), latch, 0.4 * peak);
  add(m, 0, impact(0.8 * p.mode_hz, p.zeta, 0.01, rate_hz), p.at_s, 0.7 * peak);
  add(m, 0, impact(p.mode_hz, p.zeta, 0.01, rate_hz), latch, 0.28 * peak);
  return m;
}

inline Motion bump(const BurstModel& p, double rate_hz) {
  Motion m = quiet(p.seconds, rate_hz);
  const double peak = p.peak_g * kStandardGravity;
  add(m, 0, impact(p.mode_hz, p.zeta, 0.02, rate_hz), p.at_s, peak);
  add(m, 2, impact(1.5 * p.mode_hz, p.zeta, 0.02, rate_hz), p.at_s, 0.3 * peak);
  return m;
}

struct TrafficModel {
  double low_hz = 5.0;
  double high_hz = 20.0;
  double peak_g = 0.01;
  double seconds = 40.0;
  double envelope_s = 8.0;
  unsigned seed = 2;
};

// Traffic is defined as an acceleration (band-passed noise has no mean and no drift in its
// band); its "displacement" is that acceleration integrated twice with the ends at rest, so
// that acceleration_m_s2() gives it back.
inline Motion traffic(const TrafficModel& p, double rate_hz) {
  const std::size_t n = static_cast<std::size_t>(p.seconds * rate_hz);
  std::mt19937_64 rng(p.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  // Band-pass: a 2nd-order Butterworth high-pass at low_hz then low-pass at high_hz (bilinear).
  const auto biquad = [&](double fc, bool high) {
    const double k = std::tan(std::numbers::pi * fc / rate_hz);
    const double norm = 1.0 / (1.0 + std::numbers::sqrt2 * k + k * k);
    std::array<double, 5> c{};  // b0 b1 b2 a1 a2
    if (high) {
      c = {norm, -2.0 * norm, norm, 2.0 * (k * k - 1.0) * norm,
           (1.0 - std::numbers::sqrt2 * k + k * k) * norm};
    } else {
      c = {k * k * norm, 2.0 * k * k * norm, k * k * norm, 2.0 * (k * k - 1.0) * norm,
           (1.0 - std::numbers::sqrt2 * k + k * k) * norm};
    }
    return c;
  };
  const auto filter = [&](std::vector<double> x, const std::array<double, 5>& c) {
    double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
    for (double& v : x) {
      const double y = c[0] * v + c[1] * x1 + c[2] * x2 - c[3] * y1 - c[4] * y2;
      x2 = x1;
      x1 = v;
      y2 = y1;
      y1 = y;
      v = y;
    }
    return x;
  };
  std::array<std::vector<double>, 3> a;
  for (std::vector<double>& axis : a) {
    std::vector<double> noise(n);
    for (double& v : noise) v = normal(rng);
    axis = filter(filter(noise, biquad(p.low_hz, true)), biquad(p.high_hz, false));
    double peak = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / rate_hz - 0.5 * p.seconds;
      axis[i] *= std::exp(-0.5 * (t / p.envelope_s) * (t / p.envelope_s));
      peak = std::max(peak, std::fabs(axis[i]));
    }
    for (double& v : axis) v *= p.peak_g * kStandardGravity / peak;
  }
  // Integrate twice: u[i+1] - 2 u[i] + u[i-1] = a[i] / rate^2, u[0] = u[1] = 0.
  Motion m = quiet(p.seconds, rate_hz);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      m.displacement_m[i + 1][k] = 2.0 * m.displacement_m[i][k] - m.displacement_m[i - 1][k] +
                                   a[static_cast<std::size_t>(k)][i] / (rate_hz * rate_hz);
    }
  }
  return m;
}

}  // namespace plinth::testing
