// Linked into every test binary (tests/CMakeLists.txt).
#include "tests/test_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <system_error>

namespace rastray::test {
namespace fs = std::filesystem;

namespace {

fs::path processDir() { return fs::temp_directory_path() / ("rastray-test-" + std::to_string(::getpid())); }

// "Suite.Name" of the running test, '/' of parameterised names replaced;
// the suite alone in its set-up, "program" outside any test.
std::string currentTestName() {
  const ::testing::UnitTest& unit = *::testing::UnitTest::GetInstance();
  std::string name = "program";
  if (const ::testing::TestInfo* info = unit.current_test_info())
    name = std::string(info->test_suite_name()) + "." + info->name();
  else if (const ::testing::TestSuite* suite = unit.current_test_suite())
    name = suite->name();
  for (char& c : name)
    if (c == '/') c = '_';
  return name;
}

// Removes a passing test's directory, keeps a failing one's and says where.
class ScratchCleaner : public ::testing::EmptyTestEventListener {
  void OnTestEnd(const ::testing::TestInfo& info) override {
    std::string name = std::string(info.test_suite_name()) + "." + info.name();
    for (char& c : name)
      if (c == '/') c = '_';
    const fs::path dir = processDir() / name;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return;
    if (info.result()->Failed())
      std::fprintf(stderr, "test files kept in %s\n", dir.c_str());
    else
      fs::remove_all(dir, ec);
  }
  // A suite's set-up writes under the suite's name: removed when every test
  // of it passed.
  void OnTestSuiteEnd(const ::testing::TestSuite& suite) override {
    std::string name = suite.name();
    for (char& c : name)
      if (c == '/') c = '_';
    const fs::path dir = processDir() / name;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return;
    if (suite.Failed())
      std::fprintf(stderr, "test files kept in %s\n", dir.c_str());
    else
      fs::remove_all(dir, ec);
  }
  void OnTestProgramEnd(const ::testing::UnitTest&) override {
    std::error_code ec;
    fs::remove_all(processDir() / "program", ec);
    fs::remove(processDir(), ec);  // only when empty: failing tests' files stay
  }
};

// Installed before main(); gtest's listener list outlives static set-up.
const bool installed = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new ScratchCleaner);
  return true;
}();

}  // namespace

fs::path scratchDir() {
  const fs::path dir = processDir() / currentTestName();
  fs::create_directories(dir);
  return dir;
}

std::string scratchPath(const std::string& name) { return (scratchDir() / name).string(); }

std::string scenePath(const std::string& file) { return std::string(RASTRAY_SCENES) + "/" + file; }

std::string testDataPath(const std::string& file) { return std::string(RASTRAY_TEST_DATA) + "/" + file; }

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace rastray::test
