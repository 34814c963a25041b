// Shared helper of the monitor test suites: settings that create() refuses.
#pragma once

#include <gtest/gtest.h>

#include <cstring>

#include "plinth/core/error.h"

namespace plinth::testing {

// `Component::create(s, out)` validates: it refuses `s` with `code`, and the Error names
// `field`; where `reason_part` is given, the Error's reason contains it.
template <typename Component, typename Settings>
void expect_create_refused(const Settings& s, const char* field, ErrorCode code,
                           const char* reason_part = nullptr) {
  Component unused;
  const Error e = Component::create(s, unused);
  EXPECT_EQ(e.code, code) << field;
  EXPECT_STREQ(e.field, field);
  if (reason_part != nullptr) {
    EXPECT_NE(std::strstr(e.reason, reason_part), nullptr) << e.reason;
  }
}

}  // namespace plinth::testing
