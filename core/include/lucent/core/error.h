// The one exception type lucent throws for bad input: its message is the single line a user sees.
#pragma once

#include <stdexcept>
#include <string>

namespace lucent {

/// Bad input or an unusable setting. The message names the file, field or option and what was
/// expected; the CLI prints it on one line and exits non-zero.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `text` safe to print on one terminal line: control characters (newlines, escapes) and bytes
/// that are not UTF-8 shown as \xNN, the rest as it is. Everything lucent prints that it did not
/// write itself (names, paths, a file's text in a message) goes through it.
inline std::string printable(const std::string& text) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  const auto escape = [&](unsigned char ch) {
    out += "\\x";
    out += hex[ch >> 4];
    out += hex[ch & 15];
  };
  for (std::size_t i = 0; i < text.size();) {
    const auto ch = static_cast<unsigned char>(text[i]);
    if (ch < 0x20 || ch == 0x7f) {
      escape(ch), ++i;
      continue;
    }
    if (ch < 0x80) {
      out += char(ch), ++i;
      continue;
    }
    // A well-formed UTF-8 sequence (no overlongs, no surrogates, up to U+10FFFF) is kept whole.
    const int n = ch >= 0xf0 && ch <= 0xf4 ? 4 : ch >= 0xe0 ? 3 : ch >= 0xc2 && ch < 0xe0 ? 2 : 0;
    bool ok = n > 0 && i + std::size_t(n) <= text.size();
    for (int k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
    if (ok && n == 3) {
      const auto b1 = static_cast<unsigned char>(text[i + 1]);
      ok = !(ch == 0xe0 && b1 < 0xa0) && !(ch == 0xed && b1 >= 0xa0);
    }
    if (ok && n == 4) {
      const auto b1 = static_cast<unsigned char>(text[i + 1]);
      ok = !(ch == 0xf0 && b1 < 0x90) && !(ch == 0xf4 && b1 >= 0x90);
    }
    if (!ok) {
      escape(ch), ++i;
      continue;
    }
    out.append(text, i, std::size_t(n));
    i += std::size_t(n);
  }
  return out;
}

}  // namespace lucent
