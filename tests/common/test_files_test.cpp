// The tests' own scratch directories (tests/test_files.h): each test
// writes under a directory named after itself and its process, so tests
// ctest runs at once never share a file.
#include "tests/test_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace rastray {
namespace {

TEST(ScratchDir, IsNamedAfterTheTestAndItsProcess) {
  const std::filesystem::path dir = test::scratchDir();
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  EXPECT_EQ(dir.filename().string(), "ScratchDir.IsNamedAfterTheTestAndItsProcess");
  EXPECT_EQ(dir.parent_path().filename().string(), "rastray-test-" + std::to_string(::getpid()));
  EXPECT_EQ(test::scratchPath("a.gltf"), (dir / "a.gltf").string());
}

class ScratchDirParam : public ::testing::TestWithParam<int> {};

// Parameterised names hold '/', which would make a nested directory.
TEST_P(ScratchDirParam, ParameterisedNamesAreOneDirectory) {
  const std::filesystem::path dir = test::scratchDir();
  EXPECT_EQ(dir.filename().string(),
            "Each_ScratchDirParam.ParameterisedNamesAreOneDirectory_" + std::to_string(GetParam()));
}
INSTANTIATE_TEST_SUITE_P(Each, ScratchDirParam, ::testing::Values(0, 1));

}  // namespace
}  // namespace rastray
