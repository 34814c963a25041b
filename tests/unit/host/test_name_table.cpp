#include "plinth/core/name_table.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "plinth/core/events.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"
#include "plinth/core/stepper.h"
#include "plinth/host/parse_name.h"
#include "plinth/host/run_output.h"
#include "plinth/host/sweep_impulse.h"
#include "plinth/host/sweep_parameter.h"
#include "plinth/host/sweep_search.h"

namespace plinth {
namespace {

enum class Colour : unsigned char { kRed = 0, kGreen = 1, kBlue = 7 };

constexpr NameTable<Colour, 3> kColourNames{{{
    {Colour::kRed, "red"},
    {Colour::kGreen, "green"},
    {Colour::kBlue, "blue"},
}}};

TEST(NameTable, NamesEveryValueAndFallsBackForOthers) {
  static_assert(std::string_view(kColourNames.name(Colour::kBlue)) == "blue");
  EXPECT_STREQ(kColourNames.name(Colour::kRed), "red");
  EXPECT_STREQ(kColourNames.name(static_cast<Colour>(3)), "invalid");
  EXPECT_STREQ(kColourNames.name(static_cast<Colour>(3), "?"), "?");
}

TEST(NameTable, ParsesExactlyTheNames) {
  Colour c = Colour::kRed;
  EXPECT_TRUE(kColourNames.parse("blue", c));
  EXPECT_EQ(c, Colour::kBlue);
  EXPECT_FALSE(kColourNames.parse("Blue", c));
  EXPECT_FALSE(kColourNames.parse("", c));
  EXPECT_FALSE(kColourNames.parse("blue ", c));
  EXPECT_EQ(c, Colour::kBlue);  // untouched by a failed parse
}

TEST(NameTable, RoundTripsEveryEntry) {
  for (const auto& e : kColourNames) {
    Colour c{};
    ASSERT_TRUE(kColourNames.parse(kColourNames.name(e.value), c));
    EXPECT_EQ(c, e.value);
  }
}

TEST(NameTable, ListsItsValuesInOrder) {
  constexpr auto values = kColourNames.values();
  static_assert(values.size() == 3 && values[2] == Colour::kBlue);
  EXPECT_EQ(values[0], Colour::kRed);
  EXPECT_EQ(values[1], Colour::kGreen);
}

TEST(NameTable, JoinsItsNamesAfterAPrefix) {
  static constexpr auto kText = joined_names<kColourNames>("one of ");
  static_assert(kText.size() == sizeof("one of red, green, blue"));
  EXPECT_STREQ(kText.data(), "one of red, green, blue");
  EXPECT_STREQ(joined_names<kColourNames>("").data(), "red, green, blue");
}

// Each value and each name once, and every value of the enum there: `last` is the enum's last
// value, the values being first..last without gaps.
template <class Enum, std::size_t N>
void expect_complete(const NameTable<Enum, N>& table, Enum first, Enum last) {
  std::set<int> values;
  std::set<std::string> names;
  for (const auto& e : table) {
    values.insert(static_cast<int>(e.value));
    names.insert(e.name);
  }
  EXPECT_EQ(values.size(), N);
  EXPECT_EQ(names.size(), N);
  EXPECT_EQ(*values.begin(), static_cast<int>(first));
  EXPECT_EQ(*values.rbegin(), static_cast<int>(last));
  EXPECT_EQ(static_cast<int>(last) - static_cast<int>(first) + 1, static_cast<int>(N));
}

TEST(NameTable, CoreTablesNameEveryValueOnce) {
  expect_complete(kPhaseNames, Phase::kFullContact, Phase::kLiftedOff);
  expect_complete(kCornerNames, Corner::kLeft, Corner::kRight);
  expect_complete(kEventKindNames, EventKind::kRockingStart, EventKind::kLiftOff);
  expect_complete(kStepperNames, Stepper::kRk4Located, Stepper::kSemiImplicitEuler);
  EXPECT_STREQ(phase_name(Phase::kSlideRocking), "slide_rocking");
  EXPECT_STREQ(corner_name(Corner::kRight), "right");
  EXPECT_STREQ(event_name(EventKind::kBaseStopReleased), "base_stop_released");
}

TEST(NameTable, HostTablesNameEveryValueOnce) {
  using host::ImpulseStart;
  using host::Outcome;
  using host::SweepEvent;
  using host::SweepParameter;
  expect_complete(host::kOutcomeNames, Outcome::kSurvived, Outcome::kLiftedOff);
  expect_complete(host::kSweepEventNames, SweepEvent::kSliding, SweepEvent::kLiftOff);
  expect_complete(host::kSweepParameterNames, SweepParameter::kMuS, SweepParameter::kMassRatio);
  expect_complete(host::kImpulseStartNames, ImpulseStart::kFullContact,
                  ImpulseStart::kLiftedOff);
}

// A name read from the command line: the error names the option and every name there is.
TEST(NameTable, ParseNameListsTheNamesOnError) {
  EXPECT_EQ(host::parse_name<kColourNames>("green", "--colour", "colour"), Colour::kGreen);
  try {
    (void)host::parse_name<kColourNames>("pink", "--colour", "colour");
    ADD_FAILURE() << "no InputError";
  } catch (const host::InputError& e) {
    EXPECT_STREQ(e.what(), "--colour: unknown colour 'pink' (one of red, green, blue)");
  }
}

}  // namespace
}  // namespace plinth
