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

/// A whole number in [lo, hi], written with digits only (no sign, no exponent, no fraction).
inline CLI::Validator whole_in(std::uint64_t lo, std::uint64_t hi, const std::string& what) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        std::uint64_t v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
        const bool ok = digits && ec == std::errc() && end == text.data() + text.size() && v >= lo &&
                        v <= hi;
        return ok ? std::string()
                  : "expected " + what + ", a whole number in " + range + ", got '" + text + "'";
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
