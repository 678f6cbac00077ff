// Runs one program as a child process and measures it: exit status, wall
// time and peak resident memory (getrusage's ru_maxrss of that child alone,
// read through wait4). A process's own peak RSS never goes down, so a
// study that renders many cells measures each in its own child.
// In the bench library: the peers of `rastray bench --peers` and the
// crossover study's cells run through it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rastray::crossover {

struct ChildLimits {
  double timeoutSeconds = 0;  // 0: none; past it the child is killed (SIGKILL)
  // RLIMIT_AS for the child, so a cell too big for the machine fails with
  // std::bad_alloc in the child instead of waking the OOM killer; 0: none.
  uint64_t addressSpaceBytes = 0;
  // The child's working directory; empty: this process's. (POV-Ray writes
  // only where its configuration permits, "." among them.)
  std::string workingDirectory;
};

struct ChildResult {
  bool started = false;  // fork and exec worked
  int exitCode = -1;     // when it exited
  int signal = 0;        // when a signal ended it
  bool timedOut = false;
  double wallSeconds = 0;
  uint64_t peakRssBytes = 0;
  std::string out, err;  // its stdout and stderr
};

// Runs `program` with `args` (argv[1..]); stdin is /dev/null, stdout and
// stderr go to files in `scratchDir` and are read back. When a stop is
// requested while it runs (common/interrupt.h), the child is sent SIGTERM
// (SIGKILL 5 s later) and, once it has exited, Interrupted is thrown.
ChildResult runChild(const std::string& program, const std::vector<std::string>& args,
                     const std::string& scratchDir, const ChildLimits& limits);

// This process's executable (/proc/self/exe), to run a cell with the same
// build that runs the study.
std::string selfExecutable();

// Memory the system could give a new process now (MemAvailable, bytes); 0
// when unknown.
uint64_t availableMemoryBytes();

}  // namespace rastray::crossover
