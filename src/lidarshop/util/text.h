// Small text helpers shared by the readers, the CLI and the server.
#pragma once

#include <string>

namespace lidarshop {

// `text` with the ASCII letters A-Z lowered; other bytes (UTF-8 included) unchanged, whatever the locale: file
// extensions, HTTP header names and host names are compared this way.
inline std::string AsciiLower(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

}  // namespace lidarshop
