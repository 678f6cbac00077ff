#include "common/error.h"

#include <cstdio>
#include <cstdlib>

namespace rastray {

namespace {
std::string joinWhere(const std::string& file, const std::string& element, const std::string& message) {
  std::string s = file;
  if (!element.empty()) s += ": " + element;
  return s + ": " + message;
}
}  // namespace

InputError::InputError(std::string file, std::string element, std::string message)
    : std::runtime_error(joinWhere(file, element, message)),
      file_(std::move(file)),
      element_(std::move(element)),
      message_(std::move(message)) {}

void checkFailed(const char* expr, const char* file, int line, const std::string& detail) {
  std::fprintf(stderr, "rastray: internal check failed at %s:%d: %s (%s)\n", file, line, expr,
               detail.c_str());
  std::abort();
}

}  // namespace rastray
