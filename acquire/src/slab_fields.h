// The slab fields capture.json and profile.json share: thickness_mm and side. Internal to
// lucent_acquire.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace lucent::acquire::detail {

/// Reads `thickness_mm` (a slab in (0, 10000] mm) and `side` ("reflected" | "transmitted", the far
/// side needing a thickness) from doc when present. Throws lucent::Error "<source>: field '...':
/// ..." naming the field and what was expected.
void read_slab_fields(const nlohmann::json& doc, const std::string& source,
                      std::optional<double>& thickness_mm, bool& transmitted);

}  // namespace lucent::acquire::detail
