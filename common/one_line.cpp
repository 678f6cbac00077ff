#include "common/one_line.h"

#include <cstdio>

namespace rastray {

std::string oneLine(const std::string& message) {
  std::string line;
  for (const char ch : message) {
    const unsigned char u = static_cast<unsigned char>(ch);
    if (u < 0x20 || u == 0x7F) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", u);
      line += escaped;
    } else {
      line += ch;
    }
  }
  return line;
}

}  // namespace rastray
