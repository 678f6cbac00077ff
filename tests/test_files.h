// Paths and files the tests share: the bundled scenes, the test data, and
// a directory of the running test's own for what it writes.
#pragma once

#include <filesystem>
#include <string>

namespace rastray::test {

// The running test's own directory, created on first use:
// <temp>/rastray-test-<pid>/<Suite.Name>. ctest runs the tests of one
// binary in parallel processes, so a fixed name two tests share is a race
// (two tests writing one scene file failed CI once). The directory is
// removed when the test passes and kept, with its path printed, when it
// fails.
std::filesystem::path scratchDir();
// scratchDir() / name, as a string.
std::string scratchPath(const std::string& name);

// A bundled scene: scenes/<file>.
std::string scenePath(const std::string& file);
// A file of tests/data.
std::string testDataPath(const std::string& file);

// A whole file's bytes ("" when it cannot be read).
std::string slurp(const std::filesystem::path& path);

}  // namespace rastray::test
