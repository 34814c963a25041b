// The [uncertainty] table of scene files: ranges read and checked like every other key, the
// ensemble built from them, statues drawn inside them.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <string>

#include "expect_text.h"
#include "plinth/core/ensemble_design.h"
#include "plinth/host/input_error.h"
#include "plinth/host/scene_toml.h"

namespace plinth::host {
namespace {

const std::string kIsolated = R"(
[block]
half_width = 0.3
slenderness = 3.0
eccentricity_ratio = 0.1
density = 2000.0

[base]
mass_ratio = 1.0
period = 1.0
damping_ratio = 0.1
)";

std::string error_of(const std::string& text) {
  try {
    (void)load_uncertain_scene_text(text, "s.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

TEST(SceneUncertainty, NoTableMeansOneMemberTheNominalScene) {
  const UncertainScene s = load_uncertain_scene_text(kIsolated, "s.toml");
  EXPECT_TRUE(s.uncertain.empty());
  ASSERT_EQ(s.members.size(), 1U);
  EXPECT_DOUBLE_EQ(s.members[0].h, s.nominal.h);
}

TEST(SceneUncertainty, ReadsRangesAroundTheScenesValues) {
  const UncertainScene s = load_uncertain_scene_text(kIsolated + R"(
[uncertainty.block]
slenderness = [2.8, 3.3]
eccentricity_ratio = [0.0, 0.2]
[uncertainty.base]
period = [0.85, 1.15]
)",
                                                     "s.toml");
  ASSERT_EQ(s.uncertain.size(), 3U);
  EXPECT_EQ(s.uncertain[0].table, "block");
  EXPECT_EQ(s.uncertain[0].key, "slenderness");
  EXPECT_DOUBLE_EQ(s.uncertain[0].nominal, 3.0);
  EXPECT_DOUBLE_EQ(s.uncertain[0].low, 2.8);
  EXPECT_DOUBLE_EQ(s.uncertain[0].high, 3.3);
  EXPECT_DOUBLE_EQ(s.uncertain[2].nominal, 1.0);
  EXPECT_EQ(s.uncertain[2].line, 17U);
  // Three keys: the centre and the 8 corners of the full factorial.
  ASSERT_EQ(s.members.size(), 9U);
  EXPECT_DOUBLE_EQ(s.members[0].h, 0.9);
  // Every corner holds each key at one of its ends (h = lambda b, e = eps b, T).
  for (std::size_t m = 1; m < s.members.size(); ++m) {
    const Scene& c = s.members[m];
    EXPECT_TRUE(std::abs(c.h - 0.84) < 1e-12 || std::abs(c.h - 0.99) < 1e-12) << c.h;
    const double e = c.params.block.eccentricity;
    EXPECT_TRUE(std::abs(e) < 1e-12 || std::abs(e - 0.06) < 1e-12) << e;
    const double t = c.params.base.period;
    EXPECT_TRUE(std::abs(t - 0.85) < 1e-12 || std::abs(t - 1.15) < 1e-12) << t;
  }
}

// A range need not be centred: z = -1 is low, z = +1 high, the centre the scene's own value.
TEST(SceneUncertainty, LopsidedRangesKeepTheNominalAtTheCentre) {
  const UncertainScene s = load_uncertain_scene_text(kIsolated + R"(
[uncertainty.base]
damping_ratio = [0.05, 0.1]
)",
                                                     "s.toml");
  ASSERT_EQ(s.members.size(), 3U);
  EXPECT_DOUBLE_EQ(s.members[0].params.base.damping_ratio, 0.1);
  EXPECT_DOUBLE_EQ(s.members[1].params.base.damping_ratio, 0.05);
  EXPECT_DOUBLE_EQ(s.members[2].params.base.damping_ratio, 0.1);
}

TEST(SceneUncertainty, AKeyWithAConstantDefaultMayBeUncertain) {
  const UncertainScene s = load_uncertain_scene_text(R"(
[block]
half_width = 0.3
slenderness = 4.0
density = 2000.0
[uncertainty.block]
eccentricity_ratio = [-0.1, 0.1]
)",
                                                     "s.toml");
  ASSERT_EQ(s.members.size(), 3U);
  EXPECT_DOUBLE_EQ(s.uncertain[0].nominal, 0.0);
  EXPECT_NEAR(s.members[1].params.block.eccentricity, -0.03, 1e-12);
}

TEST(SceneUncertainty, StatuesAreDrawnInsideTheRanges) {
  const UncertainScene s = load_uncertain_scene_text(kIsolated + R"(
[uncertainty.block]
slenderness = [2.8, 3.3]
[uncertainty.base]
period = [0.9, 1.2]
)",
                                                     "s.toml");
  const std::array<double, 2> low{0.0, 0.0}, high{1.0, 1.0}, mid{0.5, 0.25};
  EXPECT_NEAR(s.statue(low).h, 0.84, 1e-12);
  EXPECT_NEAR(s.statue(high).params.base.period, 1.2, 1e-12);
  EXPECT_NEAR(s.statue(mid).h, 0.3 * 3.05, 1e-12);
  EXPECT_NEAR(s.statue(mid).params.base.period, 0.975, 1e-12);
}

TEST(SceneUncertainty, LoadSceneFileAcceptsAndChecksTheTable) {
  EXPECT_NO_THROW((void)load_scene_text(kIsolated + "[uncertainty.base]\nperiod = [0.9, 1.1]\n",
                                        "s.toml"));
  EXPECT_THROW((void)load_scene_text(kIsolated + "[uncertainty.base]\nperiod = [1.1, 1.2]\n",
                                     "s.toml"),
               InputError);
}

TEST(SceneUncertainty, RefusesWhatCannotBeMeant) {
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.friction]\nstatic = [0.1, 0.3]\n"),
             "s.toml:12: uncertainty.friction: the scene has no [friction] table");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nwidth = [0.1, 0.3]\n"),
             "s.toml:13: uncertainty.block.width: unknown key (allowed in [block]: half_width,");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\ncom_height = [0.8, 1.0]\n"),
             "uncertainty.block.com_height: the scene does not give block.com_height");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nslenderness = 3.2\n"),
             "uncertainty.block.slenderness: expected a range [low, high] of two numbers");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nslenderness = [2.8, 3.1, 3.2]\n"),
             "expected a range [low, high]");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nslenderness = [2.8, \"3\"]\n"),
             "expected a range [low, high]");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nslenderness = [2.8, inf]\n"),
             "the range's ends must be finite numbers");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\nslenderness = [3.2, 2.8]\n"),
             "must hold the scene's value 3 (low <= value <= high)");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty]\nblock = 3\n"),
             "uncertainty.block: expected a table, got an integer");
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.lid]\nx = [1, 2]\n"),
             "uncertainty.lid: unknown table");
  // Each end is checked as a scene: an eccentricity past the block's half width is not one.
  EXPECT_HAS(error_of(kIsolated + "[uncertainty.block]\neccentricity_ratio = [0.0, 1.5]\n"),
             "s.toml: uncertainty: the statue with block.eccentricity_ratio = 1.5 is not a "
             "valid scene:");
}

TEST(SceneUncertainty, RefusesMoreKeysThanTheDesignHolds) {
  std::string text = R"(
[block]
half_width = 0.3
slenderness = 3.0
density = 2000.0
depth = 1.0
eccentricity_ratio = 0.0
inertia = 400.0
[base]
mass_ratio = 1.0
period = 1.0
damping_ratio = 0.1
[friction]
static = 0.5
kinetic = 0.4
[base_stops]
max_displacement = 0.2
restitution = 0.7
[support]
clearance = 0.1
[sliding_stops]
restitution = 0.5
[uncertainty.block]
half_width = [0.29, 0.31]
slenderness = [2.9, 3.1]
density = [1900, 2100]
depth = [0.9, 1.1]
eccentricity_ratio = [-0.01, 0.01]
inertia = [390, 410]
[uncertainty.base]
mass_ratio = [0.9, 1.1]
period = [0.9, 1.1]
damping_ratio = [0.09, 0.11]
[uncertainty.friction]
static = [0.45, 0.55]
kinetic = [0.35, 0.45]
[uncertainty.base_stops]
max_displacement = [0.19, 0.21]
restitution = [0.6, 0.8]
[uncertainty.support]
clearance = [0.09, 0.11]
)";
  // 14 keys: the 16-run fraction, 17 members.
  EXPECT_EQ(load_uncertain_scene_text(text, "s.toml").members.size(), 17U);
  text += "[uncertainty.sliding_stops]\nrestitution = [0.4, 0.6]\n";
  EXPECT_EQ(load_uncertain_scene_text(text, "s.toml").members.size(), 17U);  // 15
  text.insert(0, "gravity = 9.81\n");  // a top-level key: not uncertain, no change
  EXPECT_EQ(load_uncertain_scene_text(text, "s.toml").uncertain.size(), 15U);
}


// [fragility]: the statue's collapse fragility, for the box's P-wave stage (docs/pwave.md).
TEST(SceneFragility, IsReadWhenGivenAndCheckedKeyByKey) {
  EXPECT_FALSE(load_uncertain_scene_text(kIsolated, "s.toml").fragility.has_value());
  const UncertainScene s =
      load_uncertain_scene_text(kIsolated + "[fragility]\nmedian_g = 0.62\nbeta = 0.35\n", "s.toml");
  ASSERT_TRUE(s.fragility.has_value());
  EXPECT_DOUBLE_EQ(s.fragility->median_g, 0.62);
  EXPECT_DOUBLE_EQ(s.fragility->beta, 0.35);
  // The nominal statue is the same with or without it.
  EXPECT_DOUBLE_EQ(s.nominal.h, load_uncertain_scene_text(kIsolated, "s.toml").nominal.h);
  const std::string missing = error_of(kIsolated + "[fragility]\nmedian_g = 0.6\n");
  EXPECT_NE(missing.find("fragility.beta: required key missing"), std::string::npos) << missing;
  const std::string zero = error_of(kIsolated + "[fragility]\nmedian_g = 0\nbeta = 0.3\n");
  EXPECT_NE(zero.find("s.toml:13: fragility.median_g: must be a PGA above 0 g (got 0)"),
            std::string::npos)
      << zero;
  const std::string negative = error_of(kIsolated + "[fragility]\nmedian_g = 0.6\nbeta = -0.1\n");
  EXPECT_NE(negative.find("fragility.beta: must be a dispersion of 0 or more"), std::string::npos)
      << negative;
  const std::string unknown =
      error_of(kIsolated + "[fragility]\nmedian_g = 0.6\nbeta = 0.3\nmedian = 0.5\n");
  EXPECT_NE(unknown.find("fragility.median: unknown key"), std::string::npos) << unknown;
  const std::string text = error_of(kIsolated + "[fragility]\nmedian_g = \"0.6g\"\nbeta = 0.3\n");
  EXPECT_NE(text.find("fragility.median_g: expected a number"), std::string::npos) << text;
}

}  // namespace
}  // namespace plinth::host
