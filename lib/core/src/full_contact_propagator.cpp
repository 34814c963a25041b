#include "plinth/core/internal/full_contact_propagator.h"

#include <Eigen/Core>
#include <cmath>
#include <limits>

namespace plinth::internal {
namespace {

using Matrix4 = Matrix4r;

// exp(a) by scaling and squaring with a Taylor series: |a| / 2^j <= 1/2. The series stops at the
// first term that changes no entry of the sum by more than Real's epsilon relative to it (taken
// at the 4th term at the earliest: A^3 is the first power of full contact's augmented system
// with every entry it reaches), at the 24th at the latest (0.5^25 / 25! is below 1e-32). The
// rest of the series is then about a ninth of that term at most: each term's norm is at most
// |a| / 2^j / (n + 1) <= 1/10 of the last's. A partial step of the estimator (h <= 0.25 ms, an
// event located in full contact; the paper's isolated base) takes 8 terms in double, 5 in float.
Matrix4 exponential(const Matrix4& a) {
  constexpr int kFirstStop = 4;
  constexpr int kLastTerm = 24;
  const Real norm = a.cwiseAbs().colwise().sum().maxCoeff();
  int squarings = 0;
  Real scale = 1.0;
  while (norm * scale > Real(0.5) && squarings < 60) {
    scale *= Real(0.5);
    ++squarings;
  }
  const Matrix4 scaled = a * scale;
  Matrix4 sum = Matrix4::Identity();
  Matrix4 term = Matrix4::Identity();
  for (int n = 1; n <= kLastTerm; ++n) {
    term = term * scaled / static_cast<Real>(n);
    sum += term;
    if (n >= kFirstStop && (term.cwiseAbs().array() <=
                            std::numeric_limits<Real>::epsilon() * sum.cwiseAbs().array())
                               .all()) {
      break;
    }
  }
  for (int i = 0; i < squarings; ++i) sum = sum * sum;
  return sum;
}

}  // namespace

FullContactPropagator FullContactPropagator::make(const Scene& s, Real h) {
  FullContactPropagator p;
  p.step = h;
  if (!s.has_base()) return p;
  // z = (u, u', a, a'), a = u_G'' linear in the step: z' = A z.
  Matrix4 a = Matrix4::Zero();
  a(0, 1) = 1.0;
  a(1, 0) = -s.stiffness / s.total_mass;
  a(1, 1) = -s.damping / s.total_mass;
  a(1, 2) = -Real(1);
  a(2, 3) = 1.0;
  const Matrix4 e = exponential(a * h);
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
