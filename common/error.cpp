#include "common/error.h"

#include <atomic>
#include <cstdlib>

namespace rastray {

namespace {
std::string joinWhere(const std::string& file, const std::string& element, const std::string& message) {
  std::string s = file;
  if (!element.empty()) s += ": " + element;
  return s + ": " + message;
}

// Set once at start-up by the program, read by any thread that fails a check.
std::atomic<CheckFailureHandler> checkFailureHandler{nullptr};
}  // namespace

InputError::InputError(std::string file, std::string element, std::string message)
    : std::runtime_error(joinWhere(file, element, message)),
      file_(std::move(file)),
      element_(std::move(element)),
      message_(std::move(message)) {}

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
