// CLI11 validators for lucent's options: each checks the text the user typed (before conversion),
// so that "-1" for a count, "nan" or "1e999" for a length, or "5abc" never reach a command, and the
// message gives the range with its unit in %g form (never a 309-digit DBL_MAX).
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

namespace lucent::cli {

inline std::string format_g(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

/// A finite number in [lo, hi] (or (lo, hi] with lo_open), in `unit`.
inline CLI::Validator number_in(double lo, double hi, const std::string& unit,
                                bool lo_open = false) {
  const std::string range = std::string(lo_open ? "(" : "[") + format_g(lo) + ", " +
                            format_g(hi) + "]" + (unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        const bool ok = ec == std::errc() && end == text.data() + text.size() && std::isfinite(v) &&
                        (lo_open ? v > lo : v >= lo) && v <= hi;
        return ok ? std::string() : "expected a number in " + range + ", got '" + text + "'";
      },
      range, "number_in");
}

/// The digits of a whole number written plainly ("100000") or with a decimal exponent ("1e5",
/// "2.5e6"), or "" when the text is not one (a sign, a fraction left over: "1.5", "1e3.5", "-1").
inline std::string whole_number_digits(const std::string& text) {
  const std::size_t e = text.find_first_of("eE");
  const std::string mantissa = text.substr(0, e);
  const std::size_t dot = mantissa.find('.');
  std::string digits = mantissa.substr(0, dot);
  const std::string fraction = dot == std::string::npos ? "" : mantissa.substr(dot + 1);
  const auto all_digits = [](const std::string& t) {
    return t.find_first_not_of("0123456789") == std::string::npos;
  };
  if (digits.empty() || !all_digits(digits) || !all_digits(fraction)) return "";
  if (e == std::string::npos) return fraction.empty() ? digits : "";
  const std::string exponent = text.substr(e + 1);
  if (exponent.empty() || exponent.size() > 3 || !all_digits(exponent)) return "";
  digits += fraction;
  long shift = std::stol(exponent) - long(fraction.size());
  for (; shift < 0; ++shift) {  // the fraction must end in zeros the exponent moves away
    if (digits.back() != '0') return "";
    digits.pop_back();
  }
  if (digits.size() + std::size_t(shift) > 40) return "";
  return digits + std::string(std::size_t(shift), '0');
}

/// A whole number in [lo, hi], written with digits, or with a decimal exponent when the value is
/// whole (--photons 1e5, 2.5e6); no sign, no fraction left over. The text is rewritten to its
/// digits for the conversion.
inline CLI::Validator whole_in(std::uint64_t lo, std::uint64_t hi, const std::string& what) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const std::string digits = whole_number_digits(text);
        std::uint64_t v = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
        const bool ok = !digits.empty() && ec == std::errc() &&
                        end == digits.data() + digits.size() && v >= lo && v <= hi;
        if (!ok) {
          return "expected " + what + ", a whole number in " + range + " (digits, or 1e5), got '" +
                 text + "'";
        }
        text = std::to_string(v);
        return {};
      },
      what + " " + range, "whole_in");
}

/// --threads everywhere: 0 (all cores) to 1024.
inline CLI::Validator thread_count() { return whole_in(0, 1024, "a thread count (0: all cores)"); }

/// --seed everywhere: any unsigned 64-bit value, digits only ("-1" would wrap).
inline CLI::Validator seed_value() {
  return whole_in(0, UINT64_MAX, "a seed");
}

}  // namespace lucent::cli
