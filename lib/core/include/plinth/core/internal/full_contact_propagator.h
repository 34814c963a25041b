// Internal to plinth_core (tests may include it). Exact propagation of full contact over one
// step. Full contact is linear (Eq 1):
//   u'' = -u_G'' - (c u' + k u) / (m + m_b),
// so with the ground acceleration linear within the step (as a record is between samples) the
// state after a step h is exact (the state-transition method of response-spectrum codes,
// Nigam & Jennings 1969):
//   (u, u')(t + h) = Phi (u, u')(t) + Gamma0 u_G''(t) + Gamma1 u_G''(t + h).
// The matrices come from the exponential of the system augmented with the input and its slope,
// computed once per scene and step.
#pragma once

#include "plinth/core/real.h"
#include "plinth/core/scene.h"

namespace plinth::internal {

struct FullContactPropagator {
  Real step = 0.0;                                            // h, s
  Real phi[2][2] = {{Real(1), Real(0)}, {Real(0), Real(1)}};  // state transition of (u, u')
  Real gamma0[2] = {Real(0), Real(0)};  // response to u_G''(t), (m, m/s) per m/s2
  Real gamma1[2] = {Real(0), Real(0)};  // response to u_G''(t + h)

  // For the scene's base (m + m_b, c, k) and step h > 0. Without a base nothing moves: the
  // identity.
  [[nodiscard]] static FullContactPropagator make(const Scene& s, Real h);

  // (u, u') from t to t + step, with u_G'' = a0 at t and a1 at t + step, m/s2.
  void advance(Real& u, Real& u_dot, Real a0, Real a1) const {
    const Real u0 = u;
    const Real v0 = u_dot;
    // The input's part first: off the chain from one step's state to the next.
    const Real forced_u = gamma0[0] * a0 + gamma1[0] * a1;
    const Real forced_u_dot = gamma0[1] * a0 + gamma1[1] * a1;
    u = (phi[0][0] * u0 + phi[0][1] * v0) + forced_u;
    u_dot = (phi[1][0] * u0 + phi[1][1] * v0) + forced_u_dot;
  }
};

}  // namespace plinth::internal
