// Scene files: the bundled scenes load with the paper's values, every pair of alternative keys
// gives the same scene, and bad files are rejected with the file, line and key at fault.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "expect_text.h"
#include "plinth/core/scene.h"
#include "plinth/host/input_error.h"
#include "plinth/host/scene_toml.h"

namespace plinth::host {
namespace {

constexpr double kPi = std::numbers::pi;

std::string scene_path(const std::string& name) {
  return std::string(PLINTH_SOURCE_DIR) + "/sim/scenes/" + name;
}

// The message of the InputError `load` throws; fails the test when it throws none.
std::string error_of(const std::function<void()>& load) {
  try {
    load();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

std::string error_of_text(const std::string& text) {
  return error_of([&] { (void)load_scene_text(text, "test.toml"); });
}

// The reference block on the reference base, with `extra` appended inside [block] (before
// [base]) and `tail` after [base].
std::string isolated(const std::string& extra_block = "", const std::string& tail = "") {
  return "[block]\n"
         "half_width = 0.3\n"
         "slenderness = 3.0\n"
         "density = 2000.0\n" +
         extra_block +
         "[base]\n"
         "mass_ratio = 1.0\n"
         "period = 2.0\n"
         "damping_ratio = 0.2\n" +
         tail;
}

// Two scenes hold the same params (to rounding) and so the same derived values.
void expect_same(const Scene& a, const Scene& b) {
  const SceneParams& p = a.params;
  const SceneParams& q = b.params;
  EXPECT_DOUBLE_EQ(p.gravity, q.gravity);
  EXPECT_DOUBLE_EQ(p.block.half_width, q.block.half_width);
  EXPECT_DOUBLE_EQ(p.block.com_height, q.block.com_height);
  EXPECT_NEAR(p.block.eccentricity, q.block.eccentricity, 1e-15);
  EXPECT_DOUBLE_EQ(p.block.mass, q.block.mass);
  EXPECT_DOUBLE_EQ(p.block.inertia, q.block.inertia);
  EXPECT_EQ(p.has_base, q.has_base);
  EXPECT_DOUBLE_EQ(p.base.mass, q.base.mass);
  EXPECT_DOUBLE_EQ(p.base.period, q.base.period);
  EXPECT_DOUBLE_EQ(p.base.damping_ratio, q.base.damping_ratio);
  EXPECT_EQ(p.has_friction, q.has_friction);
  EXPECT_EQ(p.has_base_stops, q.has_base_stops);
  EXPECT_EQ(p.has_support, q.has_support);
  EXPECT_EQ(p.has_sliding_stops, q.has_sliding_stops);
  EXPECT_DOUBLE_EQ(a.b1, b.b1);
  EXPECT_DOUBLE_EQ(a.b2, b.b2);
  EXPECT_DOUBLE_EQ(a.impact_inertia, b.impact_inertia);
  EXPECT_DOUBLE_EQ(a.corner1.inertia, b.corner1.inertia);
  EXPECT_DOUBLE_EQ(a.stiffness, b.stiffness);
  EXPECT_DOUBLE_EQ(a.damping, b.damping);
}

// ---- The bundled scenes ------------------------------------------------------------------

TEST(BundledScenes, PaperIsolated) {
  const Scene s = load_scene_file(scene_path("paper-isolated.toml"));
  EXPECT_DOUBLE_EQ(s.g, 9.80665);
  EXPECT_DOUBLE_EQ(s.b, 0.3);
  EXPECT_DOUBLE_EQ(s.h, 0.9);
  EXPECT_DOUBLE_EQ(s.m, 2160.0);  // 2000 * 0.6 * 1.8 * 1
  EXPECT_DOUBLE_EQ(s.inertia_c, 2160.0 * (0.09 + 0.81) / 3.0);
  EXPECT_DOUBLE_EQ(s.b1, 0.3);
  EXPECT_DOUBLE_EQ(s.b2, 0.3);
  EXPECT_DOUBLE_EQ(s.corner1.critical_angle, std::atan(1.0 / 3.0));
  ASSERT_TRUE(s.has_base());
  EXPECT_DOUBLE_EQ(s.params.base.mass, 2160.0);
  EXPECT_DOUBLE_EQ(s.params.base.period, 2.0);
  EXPECT_DOUBLE_EQ(s.params.base.damping_ratio, 0.2);
  EXPECT_DOUBLE_EQ(s.total_mass, 4320.0);
  EXPECT_DOUBLE_EQ(s.omega, kPi);
  EXPECT_DOUBLE_EQ(s.stiffness, 4320.0 * kPi * kPi);
  EXPECT_DOUBLE_EQ(s.damping, 2.0 * 0.2 * 4320.0 * kPi);
  EXPECT_FALSE(s.params.has_friction);
  EXPECT_FALSE(s.params.has_base_stops);
  EXPECT_FALSE(s.params.has_support);
  EXPECT_FALSE(s.params.has_sliding_stops);
}

TEST(BundledScenes, PaperIsolatedStops) {
  const Scene s = load_scene_file(scene_path("paper-isolated-stops.toml"));
  const Scene plain = load_scene_file(scene_path("paper-isolated.toml"));
  EXPECT_EQ(s.params.block.mass, plain.params.block.mass);
  EXPECT_EQ(s.params.base.mass, plain.params.base.mass);
  EXPECT_EQ(s.impact_inertia, plain.impact_inertia);
  EXPECT_DOUBLE_EQ(s.m, 2160.0);
  EXPECT_DOUBLE_EQ(s.h, 0.9);
  EXPECT_DOUBLE_EQ(s.stiffness, 4320.0 * kPi * kPi);
  EXPECT_DOUBLE_EQ(s.params.base.damping_ratio, 0.2);
  ASSERT_TRUE(s.params.has_base_stops);
  EXPECT_DOUBLE_EQ(s.params.base_stops.max_displacement, 0.2);
  EXPECT_DOUBLE_EQ(s.params.base_stops.restitution, 0.7);
  EXPECT_FALSE(s.params.has_friction);
  EXPECT_FALSE(s.params.has_support);
  EXPECT_FALSE(s.params.has_sliding_stops);
}

TEST(BundledScenes, PaperEccentric) {
  const Scene s = load_scene_file(scene_path("paper-eccentric.toml"));
  EXPECT_DOUBLE_EQ(s.params.block.eccentricity, 0.09);  // 0.3 * b
  EXPECT_DOUBLE_EQ(s.b1, 0.39);
  EXPECT_DOUBLE_EQ(s.b2, 0.21);
  EXPECT_DOUBLE_EQ(s.m, 2160.0);
  EXPECT_DOUBLE_EQ(s.inertia_c, 648.0);
  EXPECT_DOUBLE_EQ(s.impact_inertia, 648.0 + 2160.0 * (0.81 - 0.39 * 0.21));
  EXPECT_DOUBLE_EQ(s.corner1.critical_angle, std::atan(0.39 / 0.9));
  EXPECT_DOUBLE_EQ(s.corner2.critical_angle, std::atan(0.21 / 0.9));
  EXPECT_DOUBLE_EQ(s.stiffness, 4320.0 * kPi * kPi);
  ASSERT_TRUE(s.params.has_base_stops);
  EXPECT_DOUBLE_EQ(s.params.base_stops.max_displacement, 0.2);
  EXPECT_DOUBLE_EQ(s.params.base_stops.restitution, 0.7);
}

TEST(BundledScenes, NonIsolated) {
  const Scene s = load_scene_file(scene_path("non-isolated.toml"));
  EXPECT_FALSE(s.has_base());
  EXPECT_DOUBLE_EQ(s.m, 2160.0);
  EXPECT_DOUBLE_EQ(s.h, 0.9);
  EXPECT_DOUBLE_EQ(s.total_mass, 2160.0);
  EXPECT_EQ(s.stiffness, 0.0);
  EXPECT_FALSE(s.params.has_base_stops);
  EXPECT_FALSE(s.params.has_friction);
}

// ---- Defaults and alternatives -----------------------------------------------------------

TEST(SceneToml, FileAndTextGiveTheSameScene) {
  expect_same(load_scene_file(scene_path("paper-isolated.toml")),
              load_scene_text(isolated(), "x"));
}

TEST(SceneToml, DefaultsGravityEccentricityDepthAndInertia) {
  const Scene s = load_scene_text(isolated(), "x");
  EXPECT_EQ(s.g, kStandardGravity);
  EXPECT_EQ(s.params.block.eccentricity, 0.0);
  EXPECT_DOUBLE_EQ(s.m, 2160.0);  // depth 1 m
  EXPECT_DOUBLE_EQ(s.inertia_c, homogeneous_rectangle_inertia(2160.0, 0.3, 0.9));
}

TEST(SceneToml, ReadsGravityDepthAndInertia) {
  const Scene s =
      load_scene_text("gravity = 9.81\n" + isolated("depth = 0.5\ninertia = 400.0\n"), "x");
  EXPECT_EQ(s.g, 9.81);
  EXPECT_DOUBLE_EQ(s.m, 1080.0);
  EXPECT_DOUBLE_EQ(s.params.base.mass, 1080.0);
  EXPECT_EQ(s.inertia_c, 400.0);
}

TEST(SceneToml, AcceptsIntegersWhereNumbersAreExpected) {
  const Scene s = load_scene_text(
      "gravity = 10\n[block]\nhalf_width = 1\nslenderness = 3\nmass = 2000\n"
      "[base]\nmass_ratio = 2\nperiod = 2\ndamping_ratio = 0\n",
      "x");
  EXPECT_EQ(s.g, 10.0);
  EXPECT_EQ(s.b, 1.0);
  EXPECT_EQ(s.h, 3.0);
  EXPECT_EQ(s.m, 2000.0);
  EXPECT_EQ(s.params.base.mass, 4000.0);
  EXPECT_EQ(s.params.base.period, 2.0);
  EXPECT_EQ(s.damping, 0.0);
}

TEST(SceneToml, SlendernessOrComHeight) {
  const Scene a = load_scene_text(isolated(), "x");
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\ncom_height = 0.9\ndensity = 2000.0\n"
      "[base]\nmass_ratio = 1.0\nperiod = 2.0\ndamping_ratio = 0.2\n",
      "x");
  expect_same(a, b);
  EXPECT_DOUBLE_EQ(b.h, 0.9);
}

TEST(SceneToml, DensityOrMass) {
  const Scene a = load_scene_text(isolated(), "x");
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\nmass = 2160.0\n"
      "[base]\nmass_ratio = 1.0\nperiod = 2.0\ndamping_ratio = 0.2\n",
      "x");
  expect_same(a, b);
  EXPECT_EQ(b.m, 2160.0);
}

TEST(SceneToml, EccentricityRatioOrEccentricity) {
  const Scene a = load_scene_text(isolated("eccentricity_ratio = 0.3\n"), "x");
  const Scene b = load_scene_text(isolated("eccentricity = 0.09\n"), "x");
  expect_same(a, b);
  EXPECT_DOUBLE_EQ(a.params.block.eccentricity, 0.09);
  EXPECT_DOUBLE_EQ(a.b1, 0.39);
  const Scene c = load_scene_text(isolated("eccentricity_ratio = -0.5\n"), "x");
  EXPECT_DOUBLE_EQ(c.b1, 0.15);
  EXPECT_DOUBLE_EQ(c.b2, 0.45);
}

TEST(SceneToml, MassRatioOrBaseMass) {
  const Scene a = load_scene_text(isolated(), "x");
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = 2000.0\n"
      "[base]\nmass = 2160.0\nperiod = 2.0\ndamping_ratio = 0.2\n",
      "x");
  expect_same(a, b);
}

TEST(SceneToml, PeriodOrStiffness) {
  const Scene a = load_scene_text(isolated(), "x");
  const double k = 4320.0 * kPi * kPi;
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = 2000.0\n"
      "[base]\nmass_ratio = 1.0\nstiffness = " +
          std::to_string(k) + "\ndamping_ratio = 0.2\n",
      "x");
  // std::to_string keeps 6 decimals: the period agrees to ~1e-10.
  EXPECT_NEAR(b.params.base.period, 2.0, 1e-9);
  EXPECT_NEAR(b.stiffness, a.stiffness, 1e-5);
  // Exact text of k: identical scenes.
  const Scene c = load_scene_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = 2000.0\n"
      "[base]\nmass_ratio = 1.0\nstiffness = 42636.691012706026\ndamping_ratio = 0.2\n",
      "x");
  expect_same(a, c);
}

TEST(SceneToml, DampingRatioOrDamping) {
  const Scene a = load_scene_text(isolated(), "x");
  // c = 2 xi (m + m_b) omega = 2 * 0.2 * 4320 * pi = 1728 pi.
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = 2000.0\n"
      "[base]\nmass_ratio = 1.0\nperiod = 2.0\ndamping = 5428.672105403162\n",
      "x");
  expect_same(a, b);
  EXPECT_DOUBLE_EQ(b.params.base.damping_ratio, 0.2);
  EXPECT_DOUBLE_EQ(b.damping, 1728.0 * kPi);
}

TEST(SceneToml, AllAlternativesTogether) {
  const Scene a = load_scene_text(isolated("eccentricity_ratio = 0.1\n"), "x");
  const Scene b = load_scene_text(
      "[block]\nhalf_width = 0.3\ncom_height = 0.9\neccentricity = 0.03\nmass = 2160\n"
      "[base]\nmass = 2160\nstiffness = 42636.691012706026\ndamping = 5428.672105403162\n",
      "x");
  expect_same(a, b);
}

TEST(SceneToml, FrictionSupportAndSlidingStopsParse) {
  const Scene s = load_scene_text(isolated("",
                                           "[friction]\n"
                                           "static = 0.8\n"
                                           "kinetic = 0.6\n"
                                           "[base_stops]\n"
                                           "max_displacement = 0.2\n"
                                           "restitution = 0.7\n"
                                           "[support]\n"
                                           "clearance = 0.1\n"
                                           "[sliding_stops]\n"
                                           "restitution = 0.5\n"),
                                  "x");
  ASSERT_TRUE(s.params.has_friction);
  EXPECT_EQ(s.params.friction.static_coefficient, 0.8);
  EXPECT_EQ(s.params.friction.kinetic_coefficient, 0.6);
  ASSERT_TRUE(s.params.has_base_stops);
  EXPECT_EQ(s.params.base_stops.max_displacement, 0.2);
  EXPECT_EQ(s.params.base_stops.restitution, 0.7);
  ASSERT_TRUE(s.params.has_support);
  EXPECT_EQ(s.params.support.clearance, 0.1);
  ASSERT_TRUE(s.params.has_sliding_stops);
  EXPECT_EQ(s.params.sliding_stops.restitution, 0.5);
}

TEST(SceneToml, KineticFrictionDefaultsToEightTenthsOfStatic) {
  const Scene s = load_scene_text(isolated("", "[friction]\nstatic = 0.5\n"), "x");
  EXPECT_DOUBLE_EQ(s.params.friction.kinetic_coefficient, 0.4);
}

TEST(SceneToml, InlineTablesAndDottedKeysAreTheSame) {
  const Scene a = load_scene_text(isolated(), "x");
  const Scene b = load_scene_text(
      "block = { half_width = 0.3, slenderness = 3, density = 2000 }\n"
      "base.mass_ratio = 1\nbase.period = 2\nbase.damping_ratio = 0.2\n",
      "x");
  expect_same(a, b);
}

// ---- Errors ------------------------------------------------------------------------------

TEST(SceneTomlErrors, UnknownKeyNamesItsFullDottedName) {
  const std::string msg = error_of_text(isolated("widht = 0.3\n"));
  EXPECT_HAS(msg, "test.toml:5: block.widht: unknown key");
  EXPECT_HAS(msg, "half_width");  // the allowed keys are listed
}

TEST(SceneTomlErrors, UnknownKeyInOtherTables) {
  EXPECT_HAS(error_of_text(isolated("", "[base_stops]\nmax_displacement = 0.2\nrestitution = "
                                        "0.7\neta = 0.7\n")),
             "test.toml:12: base_stops.eta: unknown key");
  EXPECT_HAS(error_of_text("gravty = 9.8\n" + isolated()), "test.toml:1: gravty: unknown key");
  EXPECT_HAS(error_of_text(isolated("", "[friction]\nstatic = 0.8\nmu = 1\n")),
             "friction.mu: unknown key");
}

TEST(SceneTomlErrors, UnknownTable) {
  EXPECT_HAS(error_of_text(isolated("", "[stops]\nrestitution = 0.7\n")),
             "test.toml:9: stops: unknown table");
  EXPECT_HAS(error_of_text(isolated("", "[block.extra]\nx = 1\n")),
             "block.extra: unknown table");
}

TEST(SceneTomlErrors, TableOfTheWrongType) {
  EXPECT_HAS(error_of_text("base = 3\n[block]\nhalf_width = 0.3\nslenderness = 3\nmass = 1\n"),
             "test.toml:1: base: expected a table, got an integer");
  EXPECT_HAS(error_of_text("[[block]]\nhalf_width = 0.3\n"), "block: expected a table, got an array");
}

TEST(SceneTomlErrors, BothAlternativesGiven) {
  const std::string msg = error_of_text(isolated("com_height = 0.9\n"));
  EXPECT_HAS(msg, "test.toml:5: block.com_height:");
  EXPECT_HAS(msg, "block.slenderness");
  EXPECT_HAS(msg, "not both");
  EXPECT_HAS(error_of_text(isolated("mass = 2160\n")), "block.density or block.mass, not both");
  EXPECT_HAS(error_of_text(isolated("eccentricity_ratio = 0\neccentricity = 0\n")),
             "block.eccentricity_ratio or block.eccentricity, not both");
  EXPECT_HAS(error_of_text(isolated("", "mass = 1\n")),
             "base.mass_ratio or base.mass, not both");
  EXPECT_HAS(error_of_text(isolated("", "stiffness = 1\n")),
             "base.period or base.stiffness, not both");
  EXPECT_HAS(error_of_text(isolated("", "damping = 1\n")),
             "base.damping_ratio or base.damping, not both");
}

TEST(SceneTomlErrors, RequiredKeyMissing) {
  const std::string msg = error_of_text("[block]\nslenderness = 3.0\ndensity = 2000.0\n");
  EXPECT_HAS(msg, "test.toml:1: block.half_width: required key missing");
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.3\ndensity = 2000.0\n"),
             "block.slenderness: required key missing (give block.slenderness or "
             "block.com_height)");
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.3\nslenderness = 3\n"),
             "block.density: required key missing");
  EXPECT_HAS(error_of_text(
                 "[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n[base]\nperiod = "
                 "2\ndamping_ratio = 0.2\n"),
             "test.toml:5: base.mass_ratio: required key missing");
  EXPECT_HAS(error_of_text(isolated("", "[friction]\nkinetic = 0.5\n")),
             "friction.static: required key missing");
  EXPECT_HAS(error_of_text(isolated("", "[base_stops]\nmax_displacement = 0.2\n")),
             "base_stops.restitution: required key missing");
  EXPECT_HAS(error_of_text("gravity = 9.8\n"), "test.toml: block: required table missing");
  EXPECT_HAS(error_of_text(""), "block: required table missing");
}

TEST(SceneTomlErrors, NegativeMass) {
  const std::string msg = error_of_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\nmass = -5.0\n");
  EXPECT_HAS(msg, "test.toml:4: block.mass: must be greater than zero (got -5)");
}

TEST(SceneTomlErrors, NegativeDensityIsNamedAsWritten) {
  const std::string msg = error_of_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = -2000\n");
  EXPECT_HAS(msg, "test.toml:4: block.density: must be greater than zero (got -2000, giving "
                  "block.mass = -2160, with block.half_width = 0.3, block.slenderness = 3)");
}

TEST(SceneTomlErrors, EccentricityRatioOfOne) {
  const std::string msg = error_of_text(isolated("eccentricity_ratio = 1.0\n"));
  EXPECT_HAS(msg, "test.toml:5: block.eccentricity_ratio:");
  EXPECT_HAS(msg, "|e| must be smaller than the half-width b");
  EXPECT_HAS(msg, "got 1,");
  EXPECT_HAS(msg, "block.eccentricity = 0.3");
  EXPECT_HAS(error_of_text(isolated("eccentricity = -0.4\n")),
             "test.toml:5: block.eccentricity: |e| must be smaller than the half-width b "
             "(|epsilon| < 1) (got -0.4, with block.half_width = 0.3)");
}

TEST(SceneTomlErrors, DampingRatioOfOne) {
  const std::string msg = error_of_text(
      "[block]\nhalf_width = 0.3\nslenderness = 3.0\ndensity = 2000\n"
      "[base]\nmass_ratio = 1\nperiod = 2\ndamping_ratio = 1.0\n");
  EXPECT_HAS(msg, "test.toml:8: base.damping_ratio: must lie in [0, 1) (got 1)");
}

TEST(SceneTomlErrors, CoreErrorsAreMappedToTheKeysUsed) {
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.5\nslenderness = -2\nmass = 1\n"),
             "test.toml:3: block.slenderness: must be greater than zero (got -2, giving "
             "block.com_height = -1, with block.half_width = 0.5)");
  EXPECT_HAS(error_of_text("[block]\nhalf_width = -0.3\ncom_height = 1\nmass = 1\n"),
             "test.toml:2: block.half_width: must be greater than zero (got -0.3)");
  EXPECT_HAS(error_of_text(isolated("inertia = 0\n")),
             "test.toml:5: block.inertia: must be greater than zero (got 0)");
  EXPECT_HAS(error_of_text("gravity = -9.8\n" + isolated()),
             "test.toml:1: gravity: must be greater than zero (got -9.8)");
  EXPECT_HAS(error_of_text(
                 "[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n[base]\nmass_ratio "
                 "= 0\nperiod = 2\ndamping_ratio = 0.2\n"),
             "test.toml:6: base.mass_ratio: must be greater than zero (got 0, giving base.mass "
             "= 0, with block.density = 2000");
  EXPECT_HAS(error_of_text(
                 "[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n[base]\nmass_ratio "
                 "= 1\nperiod = 2\ndamping = -10\n"),
             "test.toml:8: base.damping: must lie in [0, 1) (got -10, giving "
             "base.damping_ratio = ");
  EXPECT_HAS(error_of_text(
                 "[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n[base]\nmass_ratio "
                 "= 1\nperiod = 2\ndamping = 1e6\n"),
             "base.damping: must lie in [0, 1)");
  EXPECT_HAS(error_of_text(isolated("", "[friction]\nstatic = 0.5\nkinetic = 0.6\n")),
             "test.toml:11: friction.kinetic: must not exceed the static coefficient");
  EXPECT_HAS(error_of_text(isolated("", "[base_stops]\nmax_displacement = 0.2\nrestitution = "
                                        "1.5\n")),
             "test.toml:11: base_stops.restitution: must lie in [0, 1] (got 1.5)");
  EXPECT_HAS(error_of_text(isolated("", "[friction]\nstatic = 0.5\n[support]\nclearance = 0\n")),
             "test.toml:12: support.clearance: must be greater than zero (got 0)");
}

// Issue 25: a core value computed from several keys, when invalid, is blamed on the key that
// set it and names every other key it was computed from. The walk covers each derived field
// of make_scene: com_height, eccentricity, mass, inertia, base mass, period and damping ratio.
TEST(SceneTomlErrors, EveryDerivedFieldNamesAllItsInputs) {
  struct Case {
    std::string text;
    std::string blamed;               // "test.toml:LINE: KEY: "
    std::vector<std::string> inputs;  // the other keys, each "KEY = "
  };
  const std::vector<Case> cases = {
      {"[block]\nhalf_width = 1e200\nslenderness = 1e200\nmass = 1\n",
       "test.toml:3: block.slenderness: must be a finite number", {"block.half_width = "}},
      {isolated("eccentricity_ratio = 1.0\n"), "test.toml:5: block.eccentricity_ratio: ",
       {"block.half_width = 0.3"}},
      {isolated("eccentricity = -0.4\n"), "test.toml:5: block.eccentricity: ",
       {"block.half_width = 0.3"}},
      {"[block]\nhalf_width = 1e5\nslenderness = 3\ndensity = 1e300\ndepth = 1e5\n",
       "test.toml:4: block.density: must be a finite number",
       {"block.half_width = ", "block.slenderness = 3", "block.depth = "}},
      {"[block]\nhalf_width = 1e10\nslenderness = 3\nmass = 1e300\n",
       "test.toml: block.inertia: must be a finite number (not given: m (b^2 + h^2) / 3",
       {"block.mass = ", "block.half_width = ", "block.slenderness = 3"}},
      {isolated("", "").replace(isolated("", "").find("mass_ratio = 1.0"), 16,
                                "mass_ratio = 1e306"),
       "test.toml:6: base.mass_ratio: must be a finite number",
       {"block.density = 2000", "block.half_width = 0.3", "block.slenderness = 3"}},
      {"[block]\nhalf_width = 0.3\nslenderness = 3\nmass = 1e10\n[base]\nmass_ratio = 1\n"
       "stiffness = 1e-300\ndamping_ratio = 0.2\n",
       "test.toml:7: base.stiffness: must be a finite number",
       {"block.mass = ", "base.mass_ratio = 1"}},
      {isolated("", "").replace(isolated("", "").find("damping_ratio = 0.2"), 19,
                                "damping = 1e6"),
       "test.toml:8: base.damping: must lie in [0, 1)",
       {"block.density = 2000", "block.half_width = 0.3", "block.slenderness = 3",
        "base.mass_ratio = 1", "base.period = 2"}},
  };
  for (const Case& c : cases) {
    const std::string msg = error_of_text(c.text);
    EXPECT_HAS(msg, c.blamed);
    for (const std::string& input : c.inputs) EXPECT_HAS(msg, input);
  }
}

TEST(SceneTomlErrors, PartsThatNeedOthers) {
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n"
                           "[base_stops]\nmax_displacement = 0.2\nrestitution = 0.7\n"),
             "test.toml:5: base_stops: base stops need a [base]");
  EXPECT_HAS(error_of_text(isolated("", "[sliding_stops]\nrestitution = 0.7\n")),
             "test.toml:9: sliding_stops: sliding stops sit at the support's clearance");
  EXPECT_HAS(error_of_text(isolated("", "[support]\nclearance = 0.1\n")),
             "test.toml:9: support: a block that never slides (no [friction]) cannot leave the "
             "support");
}

TEST(SceneTomlErrors, StiffnessAndDepthMustBePositive) {
  EXPECT_HAS(error_of_text(
                 "[block]\nhalf_width = 0.3\nslenderness = 3\ndensity = 2000\n[base]\nmass_ratio "
                 "= 1\nstiffness = -1\ndamping_ratio = 0.2\n"),
             "test.toml:7: base.stiffness: must be greater than zero (got -1)");
  EXPECT_HAS(error_of_text(isolated("depth = 0\n")),
             "test.toml:5: block.depth: must be greater than zero (got 0)");
}

TEST(SceneTomlErrors, DepthWithMassIsRejected) {
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.3\nslenderness = 3\nmass = 10\ndepth = 1\n"),
             "test.toml:5: block.depth: is used only with block.density");
}

TEST(SceneTomlErrors, NonFiniteValues) {
  EXPECT_HAS(error_of_text(isolated("inertia = nan\n")),
             "test.toml:5: block.inertia: must be a finite number (got nan)");
  EXPECT_HAS(error_of_text("gravity = inf\n" + isolated()),
             "test.toml:1: gravity: must be a finite number (got inf)");
  EXPECT_HAS(error_of_text(isolated("", "[friction]\nstatic = -inf\n")),
             "friction.static: must be a finite number (got -inf)");
}

TEST(SceneTomlErrors, WrongTypes) {
  EXPECT_HAS(error_of_text("[block]\nhalf_width = \"0.3\"\nslenderness = 3\ndensity = 2000\n"),
             "test.toml:2: block.half_width: expected a number, got a string");
  EXPECT_HAS(error_of_text(isolated("inertia = true\n")),
             "block.inertia: expected a number, got a boolean");
  EXPECT_HAS(error_of_text(isolated("inertia = [1.0]\n")),
             "block.inertia: expected a number, got an array");
  EXPECT_HAS(error_of_text(isolated("", "[support]\nclearance = 1979-05-27\n")),
             "support.clearance: expected a number, got a date");
}

TEST(SceneTomlErrors, SyntaxErrorGivesLineAndColumn) {
  const std::string msg = error_of_text("[block]\nhalf_width = 0.3\nslenderness = = 3\n");
  EXPECT_HAS(msg, "test.toml:3:");
  EXPECT_HAS(msg, ": TOML syntax error: ");
  EXPECT_EQ(msg.rfind("test.toml:3:", 0), 0U) << msg;
  // Duplicate keys are TOML errors too.
  EXPECT_HAS(error_of_text("[block]\nhalf_width = 0.3\nhalf_width = 0.4\n"),
             "test.toml:3:");
}

TEST(SceneTomlErrors, MissingFile) {
  const std::string path = scene_path("no-such-scene.toml");
  EXPECT_EQ(error_of([&] { (void)load_scene_file(path); }),
            path + ": cannot open scene file (no such file)");
}

TEST(SceneTomlErrors, EndlessAndOversizedFilesAreRefusedUnread) {
  EXPECT_EQ(error_of([&] { (void)load_scene_file("/dev/zero"); }),
            "/dev/zero: cannot open scene file (not a regular file: a FIFO, socket or device)");
  const std::string path = ::testing::TempDir() + "plinth_test_scene_oversized.toml";
  std::ofstream(path) << "[block]\nhalf_width = 0.3\n";
  std::filesystem::resize_file(path, kMaxSceneFileBytes + 1);  // sparse: costs no disk
  EXPECT_EQ(error_of([&] { (void)load_scene_file(path); }),
            path + ": the scene file is longer than the 1 MiB limit");
  std::filesystem::remove(path);
}

TEST(SceneTomlErrors, FileErrorsNameTheFile) {
  const std::string dir = std::string(PLINTH_SOURCE_DIR) + "/sim/scenes";
  EXPECT_HAS(error_of([&] { (void)load_scene_file(dir); }), dir + ": cannot open scene file");
  const std::string path = ::testing::TempDir() + "plinth_test_scene_syntax.toml";
  {
    std::ofstream out(path);
    out << "[block]\nhalf_width = \n";
  }
  EXPECT_HAS(error_of([&] { (void)load_scene_file(path); }), path + ":2:");
  std::remove(path.c_str());
}

// A file longer than the loader's read chunk is read whole.
TEST(SceneToml, ReadsALongFile) {
  const std::string path = ::testing::TempDir() + "plinth_test_scene_long.toml";
  {
    std::ofstream out(path);
    for (int i = 0; i < 300; ++i) out << "# padding padding padding padding padding padding\n";
    out << isolated("eccentricity_ratio = 0.2\n");
  }
  const Scene s = load_scene_file(path);
  std::remove(path.c_str());
  EXPECT_DOUBLE_EQ(s.params.block.eccentricity, 0.06);
  EXPECT_DOUBLE_EQ(s.m, 2160.0);
}

}  // namespace
}  // namespace plinth::host
