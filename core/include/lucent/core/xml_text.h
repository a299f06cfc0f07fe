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

/// Text inside an XML comment: xml_escape, and no "--" (which ends a comment in XML 1.0) and no
/// trailing "-" (a name "a--b" or "x-" broke the exports' comments).
inline std::string xml_comment(const std::string& s) {
  std::string out;
  for (char ch : xml_escape(s)) {
    if (ch == '-' && !out.empty() && out.back() == '-') out += ' ';
    out += ch;
  }
  if (!out.empty() && out.back() == '-') out += ' ';
  return out;
}

}  // namespace lucent
