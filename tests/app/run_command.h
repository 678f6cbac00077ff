// Runs the real rastray binary for command-line tests: exit status, stdout
// and stderr, captured through files (no shell quoting of arguments).
#pragma once

#include <sys/types.h>

#include <functional>
#include <string>
#include <vector>

namespace rastray::test {

struct CommandResult {
  int status = -1;  // exit status; -1 when the process did not exit normally (a crash)
  std::string out;
  std::string err;
};

CommandResult runRastray(const std::vector<std::string>& args);

// Runs rastray like runRastray, but polls `ready(pid)` every 5 ms while the
// process runs and sends it `signal` once `ready` returns true (the
// interrupt tests: ready observes progress on the file system, so the
// signal lands at a known point without any test hook in the program).
// If the process ends first, no signal is sent; `signalled` says whether
// one was.
CommandResult runRastrayAndSignal(const std::vector<std::string>& args, int signal,
                                  const std::function<bool(pid_t)>& ready, bool* signalled = nullptr);

// Whether process `pid` catches SIGINT and SIGTERM (the SigCgt mask of
// /proc/PID/status): rastray installs its handlers as a command starts.
bool catchesStopSignals(pid_t pid);

}  // namespace rastray::test
