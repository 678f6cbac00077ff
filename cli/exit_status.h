// The exit status the rastray program chooses for a stopped command; SPEC
// §7's 0, 1 and 2 are returned by the commands and main.cpp directly.
#pragma once

namespace rastray {

// The exit status of a command stopped by a signal: 128 + the signal's
// number, 130 for SIGINT and 143 for SIGTERM, the status a shell reports
// for a process the signal killed, so scripts that test for it (`$? -ge
// 128`, `-eq 130`) treat a stopped rastray like any stopped program. It
// cannot collide with SPEC §7's 0, 1 and 2. This is the one place the
// choice is made.
constexpr int interruptedExitStatus(int signal) { return 128 + signal; }

}  // namespace rastray
