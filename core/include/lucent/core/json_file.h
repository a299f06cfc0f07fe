// The one bounded reading path for lucent's inputs: whole files read with a size limit (so
// /dev/zero or a mistaken multi-gigabyte argument is refused, not read until memory runs out), and
// JSON parsed with a nesting limit, duplicate keys refused and every error on one line.
#pragma once

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "lucent/core/error.h"

namespace lucent {

/// Largest JSON or CSV document lucent reads (materials, captures, profiles, configurations).
inline constexpr std::size_t kMaxDocumentBytes = std::size_t(64) << 20;
/// Deepest nesting of arrays and objects a JSON document may have (lucent's own files use < 20).
inline constexpr int kMaxJsonDepth = 128;

/// Reads the whole of `path` (a regular file, a pipe or a device) as bytes, and records it as an
/// input of the run (note_input). Throws lucent::Error "<path>: cannot open: <reason>", or
/// "<path>: larger than N MiB ..." beyond `max_bytes`.
std::string read_input_file(const std::filesystem::path& path,
                            std::size_t max_bytes = kMaxDocumentBytes);

/// Parses `text` as JSON. `source` names it in errors: "<source>: not valid JSON: ...",
/// "<source>: nesting deeper than 128 levels", "<source>: duplicate key "k" in <where>".
nlohmann::json parse_json(std::string_view text, const std::string& source);

/// read_input_file + parse_json.
nlohmann::json read_json_file(const std::filesystem::path& path);

/// Throws lucent::Error "<file>: cannot write: <field> is not finite" for the first NaN or
/// infinity in `doc` (nlohmann would write it as null). Call it before writing any JSON.
template <class Json>
void check_finite_json(const Json& doc, const std::string& file, const std::string& where = "") {
  if (doc.is_number_float()) {
    if (!std::isfinite(doc.template get<double>())) {
      throw Error(file + ": cannot write: " + (where.empty() ? std::string("the value") : where) +
                  " is not finite (lucent writes only finite numbers)");
    }
  } else if (doc.is_object()) {
    for (auto it = doc.begin(); it != doc.end(); ++it)
      check_finite_json(it.value(), file, where.empty() ? it.key() : where + "." + it.key());
  } else if (doc.is_array()) {
    for (std::size_t i = 0; i < doc.size(); ++i)
      check_finite_json(doc[i], file, where + "[" + std::to_string(i) + "]");
  }
}

}  // namespace lucent
