// Impulsive analyses (paper section 5.3.1): the motion an impulse starts with, simulated and
// predicted by the closed forms (Fig. 11 kind of map), and the smallest impulses that start
// rocking and that overturn the block against a parameter (Fig. 7 kind of curve).
//
// Impulses are applied towards corner 1 (I < 0, the sign of Eq 37's threshold for corner 1);
// CSVs and arguments give |I| in m/s. Corner 2 is corner 1 of the mirrored block (epsilon ->
// -epsilon).
#pragma once

#include <atomic>
#include <cstddef>
#include <optional>
#include <string>

#include "plinth/core/name_table.h"
#include "plinth/core/scene.h"
#include "plinth/host/sweep_parameter.h"
#include "plinth/host/sweep_plan.h"
#include "plinth/host/sweep_search.h"

namespace plinth::host {

// The motion an impulse starts with.
enum class ImpulseStart : unsigned char {
  kFullContact,   // nothing within one base period
  kSliding,       // sliding starts first
  kRocking,       // rocking starts first and its first phase ends without sliding
  kSlideRocking,  // rocking first, then sliding within the first rocking phase
  kLiftedOff,     // the block lifted off before the start was settled: outside the model
};

// The names in the impulse map's CSV.
inline constexpr NameTable<ImpulseStart, 5> kImpulseStartNames{{{
    {ImpulseStart::kFullContact, "full_contact"},
    {ImpulseStart::kSliding, "sliding"},
    {ImpulseStart::kRocking, "rocking"},
    {ImpulseStart::kSlideRocking, "slide_rocking"},
    {ImpulseStart::kLiftedOff, "lifted_off"},
}}};
[[nodiscard]] constexpr const char* impulse_start_name(ImpulseStart start) {
  return kImpulseStartNames.name(start);
}

struct SimulatedStart {
  ImpulseStart start = ImpulseStart::kFullContact;
  // kRocking, kSlideRocking: the corner the block first rocked about.
  Corner corner = Corner::kLeft;
  // kSlideRocking: |theta| / alpha of the pivot when sliding began. Eq 41 describes the onset
  // of rocking; a block on its way to overturning may slide late (docs/model.md).
  double slide_angle_ratio = 0.0;
};

// Simulates the impulse `impulse` (m/s, Eq 34's initial condition; < 0 towards corner 1) on a
// scene with a base, step dt, for one base period at most (it stops once the start is
// settled). Throws InputError when the scene has no base or the step is too large.
[[nodiscard]] SimulatedStart simulate_impulse_start(const Scene& scene, double impulse, double dt);

// The closed forms at |I| = `impulse_magnitude` towards corner 1 (needs a base).
struct ImpulseCriteria {
  double sliding_impulse = 0.0;  // C_S, Eq 38: smallest |I| that starts sliding (inf: no friction)
  double rocking_impulse = 0.0;  // C_R, Eq 37: smallest |I| that starts rocking
  double dividing_friction = 0.0;     // C_SR, Eq 39: b1 / h
  double rocking_slides_below = 0.0;  // C_RS, Eq 41 (general I_C): mu_s below which rocking slides
};
[[nodiscard]] ImpulseCriteria impulse_criteria(const Scene& scene, double impulse_magnitude);

// The paper's classification (section 5.3.1): mu_s < C_SR and |I| > C_S: sliding; mu_s > C_SR
// and |I| > C_R: slide-rocking below C_RS, rocking above; otherwise full contact.
[[nodiscard]] ImpulseStart predicted_impulse_start(const Scene& scene, double impulse_magnitude);

// Whether (|I|, mu_s) lies within `margin` (relative, in |I| and in mu_s) of a curve of the
// criteria (C_S, C_R, C_SR, C_RS) or of the line mu_s g = 2 xi omega |I|, where the damper's
// jump at t = 0+ makes the block slide at once (docs/model.md): there simulation and closed
// forms may disagree.
[[nodiscard]] bool near_criteria_curves(const Scene& scene, double impulse_magnitude,
                                        double margin);

// What near_criteria_curves found: a curve of the criteria (C_S, C_R, C_SR, C_RS), else the
// line of sliding at once (mu_s g = 2 xi omega |I|), else none. kNone without friction.
enum class NearCurve : unsigned char { kNone, kCriteria, kSlidingAtOnce };
[[nodiscard]] NearCurve near_curve(const Scene& scene, double impulse_magnitude, double margin);

// Fig. 11 kind (mode "impulse_map"): a row per (mu_s, |I|), mu_s slowest:
// "mu_s,impulse,simulated,predicted,c_s,c_r,c_sr,c_rs" (docs/sweep.md). Needs a base.
[[nodiscard]] SweepPlan plan_impulse_map(const SceneParams& base, const GridAxis& mu_axis,
                                         const GridAxis& impulse_axis, double dt);

struct ImpulseSearchSettings {
  double impulse_max = 10.0;  // largest |I| scanned, m/s
  double tolerance = 1e-3;    // bisection bracket, m/s
  int scan_points = 40;
  double dt = 5e-4;  // solver step, s
};

// Throws InputError naming --impulse-max, --impulse-tol or --dt when out of range.
void validate(const ImpulseSearchSettings& settings);

// Events after an impulse (m/s) with no ground motion after it: on a base for 5 base periods,
// on the ground until the block is at rest again; both stop at a terminal phase or once every
// event of `events` has occurred.
[[nodiscard]] Occurrences simulate_impulse_occurrences(const Scene& scene, double impulse,
                                                       double dt, EventSet events);

// The overturning impulse of a block on the ground that does not slide, towards corner 1:
// theta'(0+) = m h |I| / I_1 (Simulator::start_with_impulse) must carry C over corner 1,
// 1/2 I_1 theta'^2 = m g (r_1 - h), or, after the first impact (ratio J / I_2, Eq 23 on
// fixed ground), over corner 2; later excursions have less energy. m/s.
[[nodiscard]] double ground_overturning_impulse(const Scene& scene);

// The smallest |I| towards corner 1 that starts rocking and that overturns, searched like the
// PGA thresholds (first_occurrences: scan, bisection, checked one tolerance below). On the
// ground every impulse throws the block on a corner: rocking is 0.
struct ImpulseThresholds {
  std::optional<double> rocking;
  std::optional<double> overturned;
  std::optional<double> lift_off;  // the smallest |I| after which the model ends (lift-off)
};
[[nodiscard]] ImpulseThresholds impulse_thresholds(const Scene& scene,
                                                   const ImpulseSearchSettings& settings,
                                                   std::size_t* simulations = nullptr,
                                                   const std::atomic<bool>* stop = nullptr);

// Fig. 7 kind (mode "impulse_curve"): a row per value,
// "<param>,rocking,overturned,rocking_closed_form,overturned_closed_form,lift_off": the
// simulated thresholds and Eq 37 (on a base) or 0 and ground_overturning_impulse (on the
// ground), and the simulated lift-off threshold (above it the model ends before the others).
// With `compare_ground` (the scene must have a base), also the value's ground_counterpart's
// "overturned_ground,overturned_closed_form_ground,lift_off_ground" (its rocking impulse is 0 for every
// value, so it has no column); the same ground scene is searched once, and the
// settings line says "compare=ground".
[[nodiscard]] SweepPlan plan_impulse_curve(const SceneParams& base, SweepParameter parameter,
                                           const GridAxis& axis,
                                           const ImpulseSearchSettings& settings,
                                           bool compare_ground = false);

}  // namespace plinth::host
