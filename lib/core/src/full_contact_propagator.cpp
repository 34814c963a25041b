#include "plinth/core/internal/full_contact_propagator.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace plinth::internal {
namespace {

using Matrix4 = Matrix4r;

// Rows 0 and 1 of a 4x4 matrix.
struct TopRows {
  Real m[2][4];
};
constexpr TopRows kTopIdentity{{{Real(1), Real(0), Real(0), Real(0)},
                                {Real(0), Real(1), Real(0), Real(0)}}};

// B = A h of full contact's augmented system, z = (u, u', a, a'), a = u_G'' linear in the step:
// u'' = -(k/m) u - (c/m) u' - a, a'' = 0. Its non-zero entries only.
struct AugmentedStep {
  Real rate;       // B(0, 1) = B(2, 3) = h
  Real stiffness;  // B(1, 0) = -(k/m) h
  Real damping;    // B(1, 1) = -(c/m) h
  Real input;      // B(1, 2) = -h

  [[nodiscard]] AugmentedStep scaled(Real f) const {
    return {rate * f, stiffness * f, damping * f, input * f};
  }
  // Column sums of |B|, their largest (the 1-norm).
  [[nodiscard]] Real norm() const {
    return std::max(std::max(std::abs(stiffness), std::abs(rate) + std::abs(damping)),
                    std::max(std::abs(input), std::abs(rate)));
  }
  // Rows 0 and 1 of M B / n from rows 0 and 1 of M: B's rows 2 and 3 reach no other.
  [[nodiscard]] TopRows right_times(const TopRows& t, Real n) const {
    TopRows out;
    for (int i = 0; i < 2; ++i) {
      const Real* r = t.m[i];
      out.m[i][0] = (r[1] * stiffness) / n;
      out.m[i][1] = (r[0] * rate + r[1] * damping) / n;
      out.m[i][2] = (r[1] * input) / n;
      out.m[i][3] = (r[2] * rate) / n;
    }
    return out;
  }
};

// exp(B) by scaling and squaring with a Taylor series: |B| / 2^j <= 1/2. The series stops at the
// first term that changes no entry of the sum by more than Real's epsilon relative to it (taken
// at the 4th term at the earliest: B^3 is the first power with every entry it reaches), at the
// 24th at the latest (0.5^25 / 25! is below 1e-32). The rest of the series is then about a ninth
// of that term at most: each term's norm is at most |B| / 2^j / (n + 1) <= 1/10 of the last's. A
// partial step of the estimator (h <= 0.25 ms, an event located in full contact; the paper's
// isolated base) takes 8 terms in double, 5 in float.
// The series is summed on rows 0 and 1 alone, in scalars: rows 2 and 3 of B^n are 0 from n = 2
// on, so those of the sum are I + B's, and each term's rows 0 and 1 are the last's times B, 10
// products by B's non-zero entries in place of a 4x4 product's 64 (the same roundings: the
// products left out are by exact zeros). Each trial of an event's location in full contact makes
// one; as 4x4 products it took 5,856 instructions on the Cortex-M4F (docs/microcontroller.md).
Matrix4 exponential(const AugmentedStep& b) {
  constexpr int kFirstStop = 4;
  constexpr int kLastTerm = 24;
  constexpr Real kEpsilon = std::numeric_limits<Real>::epsilon();
  const Real norm = b.norm();
  int squarings = 0;
  Real scale = 1.0;
  while (norm * scale > Real(0.5) && squarings < 60) {
    scale *= Real(0.5);
    ++squarings;
  }
  const AugmentedStep scaled = b.scaled(scale);
  TopRows sum = kTopIdentity;
  TopRows term = kTopIdentity;
  for (int n = 1; n <= kLastTerm; ++n) {
    term = scaled.right_times(term, static_cast<Real>(n));
    bool converged = n >= kFirstStop;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 4; ++j) {
        sum.m[i][j] += term.m[i][j];
        converged = converged && std::abs(term.m[i][j]) <= kEpsilon * std::abs(sum.m[i][j]);
      }
    }
    if (converged) break;
  }
  Matrix4 e = Matrix4::Identity();  // rows 2 and 3: I + B's
  e(2, 3) = scaled.rate;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 4; ++j) e(i, j) = sum.m[i][j];
  }
  for (int i = 0; i < squarings; ++i) e = e * e;
  return e;
}

}  // namespace

FullContactPropagator FullContactPropagator::make(const Scene& s, Real h) {
  FullContactPropagator p;
  p.step = h;
  if (!s.has_base()) return p;
  // z = (u, u', a, a'), a = u_G'' linear in the step: z' = A z, B = A h.
  const AugmentedStep b{h, (-s.stiffness / s.total_mass) * h, (-s.damping / s.total_mass) * h,
                        -h};
  const Matrix4 e = exponential(b);
  // z(h) = e z(0) with a' = (a1 - a0) / h: Gamma0 = e(:, 2) - e(:, 3) / h, Gamma1 = e(:, 3) / h.
  for (int i = 0; i < 2; ++i) {
    p.phi[i][0] = e(i, 0);
    p.phi[i][1] = e(i, 1);
    p.gamma1[i] = e(i, 3) / h;
    p.gamma0[i] = e(i, 2) - p.gamma1[i];
  }
  return p;
}

}  // namespace plinth::internal
