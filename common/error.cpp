#include "common/error.h"

#include <atomic>
#include <cstdlib>

namespace rastray {

namespace {
// Set once at start-up by the program, read by any thread that fails a check.
std::atomic<CheckFailureHandler> checkFailureHandler{nullptr};
}  // namespace

CheckFailureHandler setCheckFailureHandler(CheckFailureHandler handler) {
  return checkFailureHandler.exchange(handler);
}

void checkFailed(const char* expr, const char* file, int line, const std::string& detail) {
  if (const CheckFailureHandler handler = checkFailureHandler.load())
    handler("internal check failed at " + std::string(file) + ":" + std::to_string(line) + ": " + expr +
            " (" + detail + ")");
  std::abort();
}

}  // namespace rastray
