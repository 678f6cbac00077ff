// Error messages as the front ends show them: conventions §7 promises one
// line, and a message may quote a file's own strings (or a file name) with
// line breaks or other control characters in them.
#pragma once

#include <string>

namespace rastray {

// `message` with every control character (< 0x20, 0x7F) written as \xHH.
std::string oneLine(const std::string& message);

}  // namespace rastray
