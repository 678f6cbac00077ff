// Internal checks (common/error.h): the library formats the failure and
// aborts; only the program's handler prints (here the test binaries',
// tests/print_check_failures.cpp, which prints as the rastray binary does).
#include <gtest/gtest.h>

#include <string>

#include "common/error.h"

namespace rastray {
namespace {

// The test binary runs TBB and OpenImageIO threads: re-execute for each
// death test instead of forking the threaded process.
class CheckFailureDeathTest : public testing::Test {
 protected:
  void SetUp() override { GTEST_FLAG_SET(death_test_style, "threadsafe"); }
};

TEST_F(CheckFailureDeathTest, HandlerPrintsTheExpressionAndDetailThenAborts) {
  const int two = 2;
  EXPECT_DEATH(RASTRAY_CHECK(two + 1 == 4, "two = " + std::to_string(two)),
               "^rastray: internal check failed at .*check_failure_test\\.cpp:[0-9]+: "
               "two \\+ 1 == 4 \\(two = 2\\)\n$");
}

TEST_F(CheckFailureDeathTest, WithoutAHandlerTheLibraryPrintsNothing) {
  EXPECT_DEATH(
      {
        setCheckFailureHandler(nullptr);
        RASTRAY_CHECK(false, "not printed");
      },
      "^$");
}

}  // namespace
}  // namespace rastray
