// Reading a JSON document from a file with the one-line errors every lucent reader gives.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

namespace lucent {

/// Parses `path` as JSON. Throws lucent::Error "<path>: cannot open: <reason>" or
/// "<path>: not valid JSON: parse error at line L, column C: ..." (one line).
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace lucent
