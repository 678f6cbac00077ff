// Errors that carry where they came from.
//
// Bad input (a malformed scene file, an impossible option) raises an
// InputError naming the file and the offending element; the command line
// turns it into one line on stderr and exit status 2 (SPEC §7).
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace rastray {

class InputError : public std::runtime_error {
 public:
  // what() reads "FILE: ELEMENT: MESSAGE" (ELEMENT may be empty, e.g. for
  // a file that cannot be opened at all). Inline: the OpenImageIO module
  // (common/oiio_module.h) throws it too.
  InputError(std::string file, std::string element, std::string message)
      : std::runtime_error(joinWhere(file, element, message)),
        file_(std::move(file)),
        element_(std::move(element)),
        message_(std::move(message)) {}

  const std::string& file() const { return file_; }
  const std::string& element() const { return element_; }
  const std::string& message() const { return message_; }

 private:
  static std::string joinWhere(const std::string& file, const std::string& element,
                               const std::string& message) {
    std::string s = file;
    if (!element.empty()) s += ": " + element;
    return s + ": " + message;
  }

  std::string file_, element_, message_;
};

// Internal invariant check with the values involved; on in every build
// (Release keeps assertions), because a wrong image is worse than a
// stopped one. A failure formats "internal check failed at FILE:LINE:
// EXPR (DETAIL)", hands it to the program's handler and aborts. The
// libraries never print: app/main.cpp's handler writes the line to stderr,
// so do the test binaries' (tests/print_check_failures.cpp); without a
// handler the message is lost and the process still aborts.
[[noreturn]] void checkFailed(const char* expr, const char* file, int line, const std::string& detail);

using CheckFailureHandler = void (*)(const std::string& message);
// Installs `handler` (nullptr: none) and returns the previous one. The
// handler must not return to the failed check's caller by throwing; it
// may return normally (the process then aborts).
CheckFailureHandler setCheckFailureHandler(CheckFailureHandler handler);

#define RASTRAY_CHECK(cond, detail)                                           \
  do {                                                                        \
    if (!(cond)) ::rastray::checkFailed(#cond, __FILE__, __LINE__, (detail)); \
  } while (0)

}  // namespace rastray
