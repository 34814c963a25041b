#include "plinth/core/name_table.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace plinth
