// Linked into every test binary: a failed internal check (RASTRAY_CHECK,
// common/error.h) prints its message on stderr before the process aborts,
// as the rastray binary does; the libraries themselves never print.
#include <cstdio>
#include <string>

#include "common/error.h"

namespace {

void printCheckFailure(const std::string& message) {
  std::fprintf(stderr, "rastray: %s\n", message.c_str());
  std::fflush(stderr);
}

// Installed before main() runs; the handler slot is constant-initialised
// (nullptr), so the order of static initialisation does not matter.
const bool installed = (rastray::setCheckFailureHandler(&printCheckFailure), true);

}  // namespace
