// OpenImageIO is loaded only by the commands that need it (common/oiio_module.h):
// linked in, its ~260 libraries cost every process 0.4 s before main.
// The dynamic loader's own log (LD_DEBUG=libs, on the child's stderr)
// says which libraries a run loaded.
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/app/run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

using test::runRastray;

// Runs rastray with the loader's library log on stderr.
test::CommandResult runLogged(const std::vector<std::string>& args) {
  setenv("LD_DEBUG", "libs", 1);
  const test::CommandResult r = runRastray(args);
  unsetenv("LD_DEBUG");
  return r;
}

// Whether the log has a "calling init: PATH" line whose PATH names `library`.
bool loaded(const std::string& log, const std::string& library) {
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    const size_t at = line.find("calling init: ");
    if (at != std::string::npos && line.find(library, at) != std::string::npos) return true;
  }
  return false;
}

TEST(Startup, CommandsWithoutImageFilesLeaveOpenImageIOUnloaded) {
  const auto info = runLogged({"info", test::scenePath("cornell-box.gltf")});
  ASSERT_EQ(info.status, 0) << info.err.substr(0, 2000);
  // The log works (Embree is linked in) and names no OpenImageIO library.
  EXPECT_TRUE(loaded(info.err, "libembree3")) << info.err.substr(0, 2000);
  EXPECT_FALSE(loaded(info.err, "libOpenImageIO"));
  EXPECT_FALSE(loaded(info.err, "rastray_oiio.so"));

  const auto bad = runLogged({"render", test::scenePath("cornell-box.gltf"), "--size", "0", "0", "-o",
                              test::scratchPath("never.png")});
  EXPECT_EQ(bad.status, 2);
  EXPECT_FALSE(loaded(bad.err, "libOpenImageIO"));
}

TEST(Startup, WritingAnImageLoadsTheModuleOnce) {
  const std::string png = test::scratchPath("frame.png");
  const auto r = runLogged({"render", test::scenePath("cornell-box.gltf"), "--size", "32", "24", "-o", png});
  ASSERT_EQ(r.status, 0) << r.err.substr(0, 2000);
  EXPECT_TRUE(std::filesystem::is_regular_file(png));
  EXPECT_TRUE(loaded(r.err, "rastray_oiio.so"));
  EXPECT_TRUE(loaded(r.err, "libOpenImageIO"));
}

}  // namespace
}  // namespace rastray
