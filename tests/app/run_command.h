// Runs the real rastray binary for command-line tests: exit status, stdout
// and stderr, captured through files (no shell quoting of arguments).
#pragma once

#include <string>
#include <vector>

namespace rastray::test {

struct CommandResult {
  int status = -1;  // exit status; -1 when the process did not exit normally (a crash)
  std::string out;
  std::string err;
};

CommandResult runRastray(const std::vector<std::string>& args);

}  // namespace rastray::test
