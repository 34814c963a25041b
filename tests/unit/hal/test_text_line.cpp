// TextLine (hal/text_line), the stdio-free line builder of the microcontroller's output: digits,
// padding, fixed point, hex, the extremes of int64, and a full buffer.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "plinth/hal/text_line.h"

namespace {

using plinth::hal::TextLine;

TEST(TextLine, WritesTextAndNumbers) {
  char buffer[96];
  TextLine line(buffer, sizeof buffer);
  line.put("t=").decimal(std::uint64_t{42}, 5).put(' ').decimal(std::int64_t{-7}).put(' ');
  line.fixed(-12345, 3).put(' ').fixed(5, 2).put(' ').hex(0x3A7, 3).put(' ').hex(0xB, 2);
  EXPECT_FALSE(line.failed());
  EXPECT_EQ(std::string(line.c_str()), "t=00042 -7 -12.345 0.05 3A7 0B");
  EXPECT_EQ(line.length(), std::string(line.c_str()).size());
}

TEST(TextLine, Int64Extremes) {
  char buffer[64];
  TextLine line(buffer, sizeof buffer);
  line.decimal(std::numeric_limits<std::int64_t>::min()).put(' ');
  line.decimal(std::numeric_limits<std::int64_t>::max()).put(' ');
  line.decimal(std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(std::string(line.c_str()),
            "-9223372036854775808 9223372036854775807 18446744073709551615");
}

TEST(TextLine, AFullBufferFailsAndKeepsWhatFitted) {
  char buffer[6];
  TextLine line(buffer, sizeof buffer);
  line.put("abc");
  EXPECT_FALSE(line.failed());
  line.decimal(std::uint64_t{123});  // "abc12" fits 5 + NUL; the 3 does not
  EXPECT_TRUE(line.failed());
  line.put('x');  // nothing more is written once failed
  EXPECT_EQ(std::string(line.c_str()), "abc12");
  EXPECT_EQ(line.length(), 5u);
}

}  // namespace
