// The tools' shared command-line pieces (lib/host/cli.h): the end of main.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

TEST(RunTool, ReturnsTheToolsExitCode) {
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(run_tool("plinth-x", [] { return 0; }), 0);
  EXPECT_EQ(run_tool("plinth-x", [] { return 130; }), 130);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(RunTool, AnInputErrorOrAnyOtherEndsWithOneAndTheSameMessage) {
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(run_tool("plinth-x", []() -> int { throw InputError("rec.AT2:4: no NPTS"); }), 1);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "plinth-x: error: rec.AT2:4: no NPTS\n");
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(run_tool("plinth-y", []() -> int { throw std::logic_error("a bug"); }), 1);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "plinth-y: error: a bug\n");
}

}  // namespace
}  // namespace plinth::host
