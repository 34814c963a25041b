#pragma once
// EXPECT_HAS(haystack, needle): the text contains the needle (messages, file contents).
#include <gtest/gtest.h>

#include <string>

#define EXPECT_HAS(haystack, needle)                               \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected \"" << (needle) << "\" in \"" << (haystack) << "\""
