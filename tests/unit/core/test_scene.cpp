// make_scene: every validation rule names the right field with the right code, and the derived
// quantities (corner geometry, impact inertia, base frequency, stiffness, damping) are right.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "plinth/core/scene.h"

namespace plinth {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The paper's reference scene with every optional part switched on, so that every rule runs.
SceneParams full_params() {
  SceneParams p;
  p.block.half_width = 0.3;
  p.block.com_height = 0.9;
  p.block.eccentricity = 0.0;
  p.block.mass = 2160.0;
  p.block.inertia = homogeneous_rectangle_inertia(2160.0, 0.3, 0.9);
  p.has_base = true;
  p.base.mass = 2160.0;
  p.base.period = 2.0;
  p.base.damping_ratio = 0.2;
  p.has_friction = true;
  p.friction.static_coefficient = 0.8;
  p.friction.kinetic_coefficient = 0.64;
  p.has_base_stops = true;
  p.base_stops.max_displacement = 0.2;
  p.base_stops.restitution = 0.7;
  p.has_support = true;
  p.support.clearance = 0.1;
  p.has_sliding_stops = true;
  p.sliding_stops.restitution = 0.7;
  return p;
}

TEST(MakeScene, AcceptsTheFullReferenceScene) {
  Scene s;
  const Error e = make_scene(full_params(), s);
  EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  EXPECT_EQ(e.code, ErrorCode::kOk);
}

// One validation rule: a change to the valid full scene, and the error it must give.
struct Rule {
  const char* name;
  void (*mutate)(SceneParams&);
  const char* field;
  ErrorCode code;
};

void PrintTo(const Rule& rule, std::ostream* os) { *os << rule.name; }

class ValidationRule : public ::testing::TestWithParam<Rule> {};

TEST_P(ValidationRule, NamesTheFieldAtFault) {
  const Rule& rule = GetParam();
  SceneParams p = full_params();
  rule.mutate(p);
  Scene out;
  out.b = -123.0;  // sentinel: must survive a failed make_scene
  const Error e = make_scene(p, out);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(std::string(e.field), rule.field);
  EXPECT_EQ(e.code, rule.code);
  EXPECT_FALSE(std::string(e.reason).empty());
  EXPECT_EQ(out.b, -123.0) << "out must be left unchanged on error";
}

using enum ErrorCode;

const Rule kRules[] = {
    {"gravity_nan", [](SceneParams& p) { p.gravity = kNan; }, "gravity", kNotFinite},
    {"gravity_inf", [](SceneParams& p) { p.gravity = kInf; }, "gravity", kNotFinite},
    {"gravity_zero", [](SceneParams& p) { p.gravity = 0.0; }, "gravity", kOutOfRange},
    {"gravity_negative", [](SceneParams& p) { p.gravity = -9.81; }, "gravity", kOutOfRange},

    {"half_width_zero", [](SceneParams& p) { p.block.half_width = 0.0; }, "block.half_width",
     kOutOfRange},
    {"half_width_negative", [](SceneParams& p) { p.block.half_width = -0.3; },
     "block.half_width", kOutOfRange},
    {"half_width_nan", [](SceneParams& p) { p.block.half_width = kNan; }, "block.half_width",
     kNotFinite},
    {"com_height_zero", [](SceneParams& p) { p.block.com_height = 0.0; }, "block.com_height",
     kOutOfRange},
    {"com_height_inf", [](SceneParams& p) { p.block.com_height = kInf; }, "block.com_height",
     kNotFinite},
    {"mass_negative", [](SceneParams& p) { p.block.mass = -1.0; }, "block.mass", kOutOfRange},
    {"mass_nan", [](SceneParams& p) { p.block.mass = kNan; }, "block.mass", kNotFinite},
    {"inertia_zero", [](SceneParams& p) { p.block.inertia = 0.0; }, "block.inertia",
     kOutOfRange},
    {"inertia_inf", [](SceneParams& p) { p.block.inertia = -kInf; }, "block.inertia",
     kNotFinite},
    {"eccentricity_nan", [](SceneParams& p) { p.block.eccentricity = kNan; },
     "block.eccentricity", kNotFinite},
    {"eccentricity_equal_to_b", [](SceneParams& p) { p.block.eccentricity = 0.3; },
     "block.eccentricity", kOutOfRange},
    {"eccentricity_minus_b", [](SceneParams& p) { p.block.eccentricity = -0.3; },
     "block.eccentricity", kOutOfRange},
    {"eccentricity_beyond_b", [](SceneParams& p) { p.block.eccentricity = 0.5; },
     "block.eccentricity", kOutOfRange},

    {"base_mass_zero", [](SceneParams& p) { p.base.mass = 0.0; }, "base.mass", kOutOfRange},
    {"base_mass_nan", [](SceneParams& p) { p.base.mass = kNan; }, "base.mass", kNotFinite},
    {"base_period_negative", [](SceneParams& p) { p.base.period = -2.0; }, "base.period",
     kOutOfRange},
    {"base_period_inf", [](SceneParams& p) { p.base.period = kInf; }, "base.period", kNotFinite},
    {"damping_ratio_nan", [](SceneParams& p) { p.base.damping_ratio = kNan; },
     "base.damping_ratio", kNotFinite},
    {"damping_ratio_negative", [](SceneParams& p) { p.base.damping_ratio = -0.01; },
     "base.damping_ratio", kOutOfRange},
    {"damping_ratio_one", [](SceneParams& p) { p.base.damping_ratio = 1.0; },
     "base.damping_ratio", kOutOfRange},

    {"base_stops_without_base", [](SceneParams& p) { p.has_base = false; }, "base_stops",
     kInconsistent},
    {"base_stops_u_max_zero", [](SceneParams& p) { p.base_stops.max_displacement = 0.0; },
     "base_stops.max_displacement", kOutOfRange},
    {"base_stops_u_max_nan", [](SceneParams& p) { p.base_stops.max_displacement = kNan; },
     "base_stops.max_displacement", kNotFinite},
    {"base_stops_restitution_above_one", [](SceneParams& p) { p.base_stops.restitution = 1.01; },
     "base_stops.restitution", kOutOfRange},
    {"base_stops_restitution_negative", [](SceneParams& p) { p.base_stops.restitution = -0.1; },
     "base_stops.restitution", kOutOfRange},
    {"base_stops_restitution_nan", [](SceneParams& p) { p.base_stops.restitution = kNan; },
     "base_stops.restitution", kNotFinite},

    {"friction_static_nan", [](SceneParams& p) { p.friction.static_coefficient = kNan; },
     "friction.static", kNotFinite},
    {"friction_kinetic_inf", [](SceneParams& p) { p.friction.kinetic_coefficient = kInf; },
     "friction.kinetic", kNotFinite},
    {"friction_static_negative",
     [](SceneParams& p) {
       p.friction.static_coefficient = -0.1;
       p.friction.kinetic_coefficient = -0.2;
     },
     "friction.static", kOutOfRange},
    {"friction_kinetic_negative", [](SceneParams& p) { p.friction.kinetic_coefficient = -0.1; },
     "friction.kinetic", kOutOfRange},
    {"friction_kinetic_above_static",
     [](SceneParams& p) { p.friction.kinetic_coefficient = 0.81; }, "friction.kinetic",
     kInconsistent},

    {"support_clearance_zero", [](SceneParams& p) { p.support.clearance = 0.0; },
     "support.clearance", kOutOfRange},
    {"support_clearance_nan", [](SceneParams& p) { p.support.clearance = kNan; },
     "support.clearance", kNotFinite},

    {"sliding_stops_without_support", [](SceneParams& p) { p.has_support = false; },
     "sliding_stops", kInconsistent},
    {"support_without_friction", [](SceneParams& p) { p.has_friction = false; }, "support",
     kInconsistent},
    {"sliding_stops_restitution_above_one",
     [](SceneParams& p) { p.sliding_stops.restitution = 2.0; }, "sliding_stops.restitution",
     kOutOfRange},
    {"sliding_stops_restitution_nan", [](SceneParams& p) { p.sliding_stops.restitution = kNan; },
     "sliding_stops.restitution", kNotFinite},

    // The first field at fault is the one named.
    {"first_fault_wins",
     [](SceneParams& p) {
       p.block.mass = -1.0;
       p.base.period = -1.0;
     },
     "block.mass", kOutOfRange},
};

INSTANTIATE_TEST_SUITE_P(AllRules, ValidationRule, ::testing::ValuesIn(kRules),
                         [](const ::testing::TestParamInfo<Rule>& rule_info) {
                           return std::string(rule_info.param.name);
                         });

// Values on the edge of their range, and parts that are switched off, are accepted.
TEST(MakeScene, AcceptsBoundaryValues) {
  SceneParams p = full_params();
  p.block.eccentricity = 0.2999;
  p.base.damping_ratio = 0.0;
  p.base_stops.restitution = 1.0;
  p.sliding_stops.restitution = 0.0;
  p.friction.static_coefficient = 0.5;
  p.friction.kinetic_coefficient = 0.5;  // mu_k == mu_s is allowed
  Scene s;
  EXPECT_TRUE(make_scene(p, s).ok());
  p.friction.static_coefficient = 0.0;
  p.friction.kinetic_coefficient = 0.0;
  p.base_stops.restitution = 0.0;
  p.block.eccentricity = -0.2999;
  EXPECT_TRUE(make_scene(p, s).ok());
}

TEST(MakeScene, IgnoresTheValuesOfPartsThatAreAbsent) {
  SceneParams p = full_params();
  p.has_base = false;
  p.has_base_stops = false;
  p.base.mass = -1.0;
  p.base.period = kNan;
  p.base.damping_ratio = 5.0;
  p.base_stops.restitution = 7.0;
  p.has_friction = false;
  p.friction.static_coefficient = kNan;
  p.has_support = false;
  p.has_sliding_stops = false;
  p.support.clearance = -1.0;
  p.sliding_stops.restitution = -1.0;
  Scene s;
  const Error e = make_scene(p, s);
  EXPECT_TRUE(e.ok()) << e.field;
  EXPECT_FALSE(s.has_base());
  EXPECT_DOUBLE_EQ(s.total_mass, 2160.0);
  EXPECT_EQ(s.omega, 0.0);
  EXPECT_EQ(s.stiffness, 0.0);
  EXPECT_EQ(s.damping, 0.0);
}

TEST(HomogeneousRectangleInertia, IsMassTimesBSquaredPlusHSquaredOverThree) {
  static_assert(homogeneous_rectangle_inertia(3.0, 1.0, 2.0) == 5.0);
  EXPECT_DOUBLE_EQ(homogeneous_rectangle_inertia(2160.0, 0.3, 0.9), 2160.0 * 0.9 / 3.0);
  EXPECT_DOUBLE_EQ(homogeneous_rectangle_inertia(2160.0, 0.3, 0.9), 648.0);
  // A rectangle 2b x 2h: I = m (4b^2 + 4h^2) / 12.
  EXPECT_DOUBLE_EQ(homogeneous_rectangle_inertia(10.0, 0.5, 1.5),
                   10.0 * (1.0 * 1.0 + 3.0 * 3.0) / 12.0);
}

TEST(MakeScene, DerivesTheSymmetricBlockOnTheBase) {
  SceneParams p = full_params();
  Scene s;
  ASSERT_TRUE(make_scene(p, s).ok());
  const double m = 2160.0, b = 0.3, h = 0.9, ic = 648.0;
  EXPECT_DOUBLE_EQ(s.b, b);
  EXPECT_DOUBLE_EQ(s.h, h);
  EXPECT_DOUBLE_EQ(s.m, m);
  EXPECT_DOUBLE_EQ(s.inertia_c, ic);
  EXPECT_DOUBLE_EQ(s.g, kStandardGravity);
  EXPECT_DOUBLE_EQ(s.b1, b);
  EXPECT_DOUBLE_EQ(s.b2, b);
  EXPECT_TRUE(s.has_base());

  const double r = std::sqrt(b * b + h * h);
  for (const CornerGeometry* c : {&s.corner1, &s.corner2}) {
    EXPECT_DOUBLE_EQ(c->radius, r);
    EXPECT_DOUBLE_EQ(c->inertia, ic + m * r * r);
    // Homogeneous block: I_O = 4/3 m R^2.
    EXPECT_NEAR(c->inertia, 4.0 / 3.0 * m * r * r, 1e-9);
    EXPECT_DOUBLE_EQ(c->critical_angle, std::atan(1.0 / 3.0));
    EXPECT_DOUBLE_EQ(c->onset_ratio, 1.0 / 3.0);
  }
  EXPECT_DOUBLE_EQ(s.corner1.offset, b);
  EXPECT_DOUBLE_EQ(s.corner2.offset, -b);
  EXPECT_EQ(s.corner1.sign, 1.0);
  EXPECT_EQ(s.corner2.sign, -1.0);
  EXPECT_EQ(&s.corner(Corner::kLeft), &s.corner1);
  EXPECT_EQ(&s.corner(Corner::kRight), &s.corner2);

  // J = I_C + m (h^2 - b1 b2) = m (b^2 + h^2)/3 + m (h^2 - b^2).
  EXPECT_DOUBLE_EQ(s.impact_inertia, ic + m * (h * h - b * b));
  // Housner's coefficient of restitution for this block: J / I_O = 1 - 3/2 sin^2 alpha.
  const double alpha = std::atan(b / h);
  EXPECT_NEAR(s.impact_inertia / s.corner1.inertia,
              1.0 - 1.5 * std::sin(alpha) * std::sin(alpha), 1e-12);

  const double total = 2.0 * m;
  const double omega = std::numbers::pi;  // 2 pi / T with T = 2 s
  EXPECT_DOUBLE_EQ(s.total_mass, total);
  EXPECT_DOUBLE_EQ(s.omega, omega);
  EXPECT_DOUBLE_EQ(s.stiffness, total * omega * omega);
  EXPECT_DOUBLE_EQ(s.stiffness, 4320.0 * std::numbers::pi * std::numbers::pi);
  EXPECT_DOUBLE_EQ(s.damping, 2.0 * 0.2 * total * omega);
  EXPECT_DOUBLE_EQ(s.damping, 1728.0 * std::numbers::pi);

  // The params are kept as given.
  EXPECT_EQ(s.params.base.period, 2.0);
  EXPECT_EQ(s.params.friction.kinetic_coefficient, 0.64);
  EXPECT_TRUE(s.params.has_sliding_stops);
}

TEST(MakeScene, DerivesTheEccentricBlock) {
  SceneParams p = full_params();
  const double b = 0.3, h = 0.9, m = 2160.0, ic = 500.0, e = 0.09;
  p.block.eccentricity = e;
  p.block.inertia = ic;
  p.gravity = 9.81;
  Scene s;
  ASSERT_TRUE(make_scene(p, s).ok());
  const double b1 = b + e, b2 = b - e;
  EXPECT_DOUBLE_EQ(s.b1, b1);
  EXPECT_DOUBLE_EQ(s.b2, b2);
  EXPECT_DOUBLE_EQ(s.g, 9.81);
  EXPECT_DOUBLE_EQ(s.inertia_c, ic);

  EXPECT_DOUBLE_EQ(s.corner1.offset, b1);
  EXPECT_DOUBLE_EQ(s.corner2.offset, -b2);
  EXPECT_DOUBLE_EQ(s.corner1.radius, std::sqrt(b1 * b1 + h * h));
  EXPECT_DOUBLE_EQ(s.corner2.radius, std::sqrt(b2 * b2 + h * h));
  EXPECT_DOUBLE_EQ(s.corner1.inertia, ic + m * (b1 * b1 + h * h));
  EXPECT_DOUBLE_EQ(s.corner2.inertia, ic + m * (b2 * b2 + h * h));
  EXPECT_DOUBLE_EQ(s.corner1.critical_angle, std::atan(b1 / h));
  EXPECT_DOUBLE_EQ(s.corner2.critical_angle, std::atan(b2 / h));
  EXPECT_DOUBLE_EQ(s.corner1.onset_ratio, b1 / h);
  EXPECT_DOUBLE_EQ(s.corner2.onset_ratio, b2 / h);
  EXPECT_GT(s.corner1.critical_angle, s.corner2.critical_angle);

  EXPECT_DOUBLE_EQ(s.impact_inertia, ic + m * (h * h - b1 * b2));
  // The same J either way: I_1 - m b1 (b1 + b2) = I_2 - m b2 (b1 + b2).
  EXPECT_NEAR(s.impact_inertia, s.corner1.inertia - m * b1 * (b1 + b2), 1e-9);
  EXPECT_NEAR(s.impact_inertia, s.corner2.inertia - m * b2 * (b1 + b2), 1e-9);
}

TEST(MakeScene, DerivesTheBaseFromItsPeriodAndMass) {
  SceneParams p = full_params();
  p.base.mass = 1080.0;  // m_b = m/2
  p.base.period = 3.0;
  p.base.damping_ratio = 0.1;
  Scene s;
  ASSERT_TRUE(make_scene(p, s).ok());
  const double total = 3240.0;
  const double omega = 2.0 * std::numbers::pi / 3.0;
  EXPECT_DOUBLE_EQ(s.total_mass, total);
  EXPECT_DOUBLE_EQ(s.omega, omega);
  EXPECT_DOUBLE_EQ(s.stiffness, total * omega * omega);
  EXPECT_DOUBLE_EQ(s.damping, 2.0 * 0.1 * total * omega);
  // Period back from the stiffness: T = 2 pi sqrt((m + m_b) / k).
  EXPECT_DOUBLE_EQ(2.0 * std::numbers::pi * std::sqrt(total / s.stiffness), 3.0);
}

}  // namespace
}  // namespace plinth
