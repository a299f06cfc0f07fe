// Text for XML files lucent writes (Mitsuba and MaterialX exports, the SVG plots' title and
// description): the five markup characters escaped, and the control characters XML 1.0 does not
// allow (all below 0x20 except tab, line feed and carriage return) dropped.
#pragma once

#include <string>

namespace lucent {

inline std::string xml_escape(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (static_cast<unsigned char>(ch) >= 0x20 || ch == '\t' || ch == '\n' || ch == '\r')
          out += ch;
    }
  }
  return out;
}

}  // namespace lucent
