// The continuous state of the hybrid system and its discrete mode.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"

namespace plinth {

// y = (u, x, theta, u', x', theta'): base displacement relative to the ground, sliding of the
// body on the base (0 until sliding is modelled), rotation about the active corner (> 0 about
// corner 1), and their rates. SI units: m, m, rad, m/s, m/s, rad/s.
using State = Eigen::Matrix<Real, 6, 1>;

enum StateIndex : Eigen::Index { kU = 0, kX = 1, kTheta = 2, kUDot = 3, kXDot = 4, kThetaDot = 5 };

// Accelerations (u'', x'', theta'') of one phase's equations of motion.
struct Accelerations {
  Real u = 0.0;      // m/s2, relative to the ground
  Real x = 0.0;      // m/s2
  Real theta = 0.0;  // rad/s2
};

// The terminal phases come last (Mode::terminal compares once).
enum class Phase : std::uint8_t {
  kFullContact,
  kSliding,
  kRocking,
  kSlideRocking,
  kOverturned,
  kFell,
  // The block lost contact with its support (its normal force fell to zero, guards.h kLiftOff):
  // the model has no free flight, so the run ends here, outside the model.
  kLiftedOff,
};

// The names used in plinth-sim's CSV and in the monitor's status lines.
inline constexpr NameTable<Phase, 7> kPhaseNames{{{
    {Phase::kFullContact, "full_contact"},
    {Phase::kSliding, "sliding"},
    {Phase::kRocking, "rocking"},
    {Phase::kSlideRocking, "slide_rocking"},
    {Phase::kOverturned, "overturned"},
    {Phase::kFell, "fell"},
    {Phase::kLiftedOff, "lifted_off"},
}}};
[[nodiscard]] constexpr const char* phase_name(Phase phase) { return kPhaseNames.name(phase); }

// The discrete part of the hybrid state.
struct Mode {
  Phase phase = Phase::kFullContact;
  Corner corner = Corner::kLeft;  // rocking phases: the corner the block turns about
  // +1 / -1: the base rests against the right / left base stop (u = +-u_max, u' = 0) after
  // its rebounds died out; 0: the base moves freely. See resets.h, base_stop_reset.
  std::int8_t held_stop = 0;
  // Sliding phases: sign of x' (+1: the block slides right on the base), fixed for the phase.
  std::int8_t slide_direction = 0;
  // -1 / +1: the block overhangs the support's left / right edge (x < -x_hat / x > x_hat), so
  // rocking about that side turns about the support's corner (Eqs 13-14); 0: on the support.
  std::int8_t overhang = 0;

  [[nodiscard]] bool sliding() const {
    return phase == Phase::kSliding || phase == Phase::kSlideRocking;
  }

  [[nodiscard]] bool rocking() const {
    return phase == Phase::kRocking || phase == Phase::kSlideRocking;
  }
  // The block overturned or fell off the base.
  [[nodiscard]] bool collapsed() const {
    return phase == Phase::kOverturned || phase == Phase::kFell;
  }
  // The run has ended: a collapse, or the model's validity (kLiftedOff).
  [[nodiscard]] bool terminal() const { return phase >= Phase::kOverturned; }
};

}  // namespace plinth
