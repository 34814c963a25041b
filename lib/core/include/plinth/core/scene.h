// What is physically there: the block, the isolated base (or none), the stops.
// `SceneParams` is what a scene file says, in SI units; `Scene` is the validated scene with
// the derived quantities of the paper computed once (Eqs 9, 26, 27 and the impact maps).
#pragma once

#include "plinth/core/error.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"

namespace plinth {

inline constexpr Real kStandardGravity = Real(9.80665);  // m/s2

struct BlockParams {
  Real half_width = 0.0;    // b, m
  Real com_height = 0.0;    // h, height of the centre of mass C above the base, m
  Real eccentricity = 0.0;  // e = b1 - b, m; positive when C lies right of the middle M
  Real mass = 0.0;          // m, kg
  Real inertia = 0.0;       // I_C, polar inertia about C, kg m2
};

struct BaseParams {
  Real mass = 0.0;           // m_b, kg
  Real period = 0.0;         // T, s (Eq 26)
  Real damping_ratio = 0.0;  // xi (Eq 26)
};

struct FrictionParams {
  Real static_coefficient = 0.0;   // mu_s
  Real kinetic_coefficient = 0.0;  // mu_k
};

struct BaseStopParams {
  Real max_displacement = 0.0;  // u_max, m (Eq 28)
  Real restitution = 0.0;       // eta_i (Eq 29)
};

struct SupportParams {
  Real clearance = 0.0;  // x_hat, m: sliding before the block overhangs the support
};

struct SlidingStopParams {
  Real restitution = 0.0;  // eta_s (Eq 32)
};

struct SceneParams {
  Real gravity = kStandardGravity;  // g, m/s2
  BlockParams block;
  bool has_base = false;  // false: the block stands on the ground (non-isolated system)
  BaseParams base;
  bool has_friction = false;  // false: the block never slides
  FrictionParams friction;
  bool has_base_stops = false;
  BaseStopParams base_stops;
  bool has_support = false;  // false: the support is wide enough never to be left
  SupportParams support;
  bool has_sliding_stops = false;
  SlidingStopParams sliding_stops;
};

// Which rocking corner: corner 1 is the left one (theta > 0), corner 2 the right one
// (theta < 0), as in the paper's Fig. 3.
enum class Corner : unsigned char { kLeft = 1, kRight = 2 };

// The names used in plinth-sim's outputs and the monitor's status lines.
inline constexpr NameTable<Corner, 2> kCornerNames{{{
    {Corner::kLeft, "left"},
    {Corner::kRight, "right"},
}}};
[[nodiscard]] constexpr const char* corner_name(Corner corner) { return kCornerNames.name(corner); }

// Geometry of rocking about one corner, in the body frame: the vector from the corner to C is
// (offset, h); offset = b1 for corner 1 and -b2 for corner 2, which turns Eqs 8-9 for corner 1
// into the equations of either corner.
struct CornerGeometry {
  Real offset = 0.0;          // horizontal distance corner -> C at theta = 0, signed, m
  Real radius = 0.0;          // r_i = sqrt(b_i^2 + h^2), m
  Real inertia = 0.0;         // I_i = I_C + m r_i^2, kg m2
  Real critical_angle = 0.0;  // alpha_i = atan(b_i / h), rad; |theta| past it overturns
  Real onset_ratio = 0.0;     // b_i / h: Eq 16 threshold over (g + vg'')
  Real sign = 0.0;            // +1 for corner 1 (theta > 0), -1 for corner 2
};

struct Scene {
  SceneParams params;

  // Derived once by make_scene.
  Real b = Real(0), h = Real(0), m = Real(0), inertia_c = Real(0), g = 0.0;
  Real b1 = Real(0), b2 = 0.0;  // distances from C's vertical to corners 1 and 2, m
  CornerGeometry corner1, corner2;
  // Rotational inertia about the new corner carried through a theta = 0 impact:
  // J = I_C + m h^2 - m b1 b2 (the same for either direction; see resets.h, Eq 21).
  Real impact_inertia = 0.0;
  Real total_mass = 0.0;  // m + m_b (m alone when there is no base), kg
  Real omega = 0.0;       // base circular frequency, rad/s (Eq 26)
  Real stiffness = 0.0;   // k, N/m
  Real damping = 0.0;     // c, N s/m

  [[nodiscard]] const CornerGeometry& corner(Corner c) const {
    return c == Corner::kLeft ? corner1 : corner2;
  }
  [[nodiscard]] bool has_base() const { return params.has_base; }
};

// What the model of a scene carries, fixed once when the scene is loaded: the simulator compiles
// in the guards and resets of exactly these (internal/guards.h, active_guards), and they say
// which events a scene can have.
struct Features {
  bool base = false;           // an isolated base (u is a degree of freedom)
  bool base_stops = false;     // security stops on the base (Eqs 28-29)
  bool sliding = false;        // friction is finite: sliding phases exist (Eqs 2-5, 10-15, 17-20)
  bool support_edge = false;   // the block can overhang the support and fall (Eqs 13-14)
  bool sliding_stops = false;  // sliding stops at |x| = x_hat (Eqs 30-32)
};

[[nodiscard]] constexpr Features features_of(const Scene& s) {
  const SceneParams& p = s.params;
  return {p.has_base, p.has_base_stops, p.has_friction,
          p.has_friction && p.has_support && !p.has_sliding_stops,
          p.has_friction && p.has_sliding_stops};
}

// Geometry of rocking about a pivot `distance` (b_i or b_hat_i, m) from C's vertical, on the
// side `sign` (+1: corner 1, -1: corner 2).
[[nodiscard]] CornerGeometry corner_geometry(const Scene& s, Real distance, Real sign);

// Validates `params` and fills `out`. On error, `out` is left unchanged and the Error names the
// first field at fault.
[[nodiscard]] Error make_scene(const SceneParams& params, Scene& out);

// Polar inertia about C of a homogeneous rectangle 2b wide and 2h tall: m (b^2 + h^2) / 3.
[[nodiscard]] constexpr Real homogeneous_rectangle_inertia(Real mass, Real half_width,
                                                           Real com_height) {
  return mass * (half_width * half_width + com_height * com_height) / Real(3);
}

}  // namespace plinth
