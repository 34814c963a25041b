#include "plinth/core/scene.h"

#include <cmath>
#include <numbers>

#include "plinth/core/checks.h"

namespace plinth {
namespace {

constexpr Error fail(ErrorCode code, const char* field, const char* reason) {
  return Error{code, field, reason};
}

// Checks `value` is finite and in [0, 1].
Error check_unit_interval(Real value, const char* field) {
  if (!std::isfinite(value)) return fail(ErrorCode::kNotFinite, field, "must be a finite number");
  if (value < Real(0) || value > Real(1))
    return fail(ErrorCode::kOutOfRange, field, "must lie in [0, 1]");
  return ok_error();
}

Error validate(const SceneParams& p) {
  PLINTH_TRY(check_positive(p.gravity, "gravity"));
  const BlockParams& blk = p.block;
  PLINTH_TRY(check_positive(blk.half_width, "block.half_width"));
  PLINTH_TRY(check_positive(blk.com_height, "block.com_height"));
  PLINTH_TRY(check_positive(blk.mass, "block.mass"));
  PLINTH_TRY(check_positive(blk.inertia, "block.inertia"));
  if (!std::isfinite(blk.eccentricity)) {
    return fail(ErrorCode::kNotFinite, "block.eccentricity", "must be a finite number");
  }
  if (std::fabs(blk.eccentricity) >= blk.half_width) {
    return fail(ErrorCode::kOutOfRange, "block.eccentricity",
                "|e| must be smaller than the half-width b (|epsilon| < 1)");
  }
  if (p.has_base) {
    PLINTH_TRY(check_positive(p.base.mass, "base.mass"));
    PLINTH_TRY(check_positive(p.base.period, "base.period"));
    if (!std::isfinite(p.base.damping_ratio)) {
      return fail(ErrorCode::kNotFinite, "base.damping_ratio", "must be a finite number");
    }
    if (p.base.damping_ratio < Real(0) || p.base.damping_ratio >= Real(1)) {
      return fail(ErrorCode::kOutOfRange, "base.damping_ratio", "must lie in [0, 1)");
    }
  }
  if (p.has_base_stops) {
    if (!p.has_base) {
      return fail(ErrorCode::kInconsistent, "base_stops", "base stops need a [base]");
    }
    PLINTH_TRY(check_positive(p.base_stops.max_displacement, "base_stops.max_displacement"));
    PLINTH_TRY(check_unit_interval(p.base_stops.restitution, "base_stops.restitution"));
  }
  if (p.has_friction) {
    const FrictionParams& f = p.friction;
    if (!std::isfinite(f.static_coefficient)) {
      return fail(ErrorCode::kNotFinite, "friction.static", "must be a finite number");
    }
    if (!std::isfinite(f.kinetic_coefficient)) {
      return fail(ErrorCode::kNotFinite, "friction.kinetic", "must be a finite number");
    }
    if (f.static_coefficient < Real(0)) {
      return fail(ErrorCode::kOutOfRange, "friction.static", "must not be negative");
    }
    if (f.kinetic_coefficient < Real(0)) {
      return fail(ErrorCode::kOutOfRange, "friction.kinetic", "must not be negative");
    }
    if (f.kinetic_coefficient > f.static_coefficient) {
      return fail(ErrorCode::kInconsistent, "friction.kinetic",
                  "must not exceed the static coefficient (mu_k <= mu_s)");
    }
  }
  if (p.has_support) {
    if (!p.has_friction) {
      return fail(ErrorCode::kInconsistent, "support",
                  "a block that never slides (no [friction]) cannot leave the support");
    }
    PLINTH_TRY(check_positive(p.support.clearance, "support.clearance"));
  }
  if (p.has_sliding_stops) {
    if (!p.has_support) {
      return fail(ErrorCode::kInconsistent, "sliding_stops",
                  "sliding stops sit at the support's clearance: they need a [support]");
    }
    PLINTH_TRY(check_unit_interval(p.sliding_stops.restitution, "sliding_stops.restitution"));
  }
  return ok_error();
}

CornerGeometry make_corner(Real distance, Real sign, Real h, Real m, Real inertia_c) {
  CornerGeometry c;
  c.offset = sign * distance;
  c.radius = std::hypot(distance, h);
  c.inertia = inertia_c + m * (distance * distance + h * h);
  c.critical_angle = std::atan2(distance, h);
  c.onset_ratio = distance / h;
  c.sign = sign;
  return c;
}

}  // namespace

CornerGeometry corner_geometry(const Scene& s, Real distance, Real sign) {
  return make_corner(distance, sign, s.h, s.m, s.inertia_c);
}

Error make_scene(const SceneParams& params, Scene& out) {
  PLINTH_TRY(validate(params));
  Scene s;
  s.params = params;
  s.b = params.block.half_width;
  s.h = params.block.com_height;
  s.m = params.block.mass;
  s.inertia_c = params.block.inertia;
  s.g = params.gravity;
  s.b1 = s.b + params.block.eccentricity;
  s.b2 = s.b - params.block.eccentricity;
  s.corner1 = make_corner(s.b1, +Real(1), s.h, s.m, s.inertia_c);
  s.corner2 = make_corner(s.b2, -Real(1), s.h, s.m, s.inertia_c);
  s.impact_inertia = s.inertia_c + s.m * (s.h * s.h - s.b1 * s.b2);
  if (params.has_base) {
    s.total_mass = s.m + params.base.mass;
    s.omega = Real(2) * std::numbers::pi_v<Real> / params.base.period;
    s.stiffness = s.total_mass * s.omega * s.omega;                        // Eq 26
    s.damping = Real(2) * params.base.damping_ratio * s.total_mass * s.omega;  // Eq 26
  } else {
    s.total_mass = s.m;
  }
  out = s;
  return ok_error();
}

}  // namespace plinth
