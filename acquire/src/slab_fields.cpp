// The slab fields of capture.json and profile.json (slab_fields.h).
#include "slab_fields.h"

#include <cmath>

#include "lucent/core/error.h"

namespace lucent::acquire::detail {

void read_slab_fields(const nlohmann::json& doc, const std::string& source,
                      std::optional<double>& thickness_mm, bool& transmitted) {
  const auto fail = [&](const std::string& field, const std::string& what) {
    throw Error(source + ": field '" + field + "': " + what);
  };
  if (doc.contains("thickness_mm")) {
    const nlohmann::json& t = doc["thickness_mm"];
    if (!t.is_number() || !std::isfinite(t.get<double>()) || !(t.get<double>() > 0) ||
        !(t.get<double>() <= 1e4))
      fail("thickness_mm", "expected a slab thickness in (0, 10000] mm");
    thickness_mm = t.get<double>();
  }
  if (doc.contains("side")) {
    const nlohmann::json& s = doc["side"];
    if (!s.is_string() || (s != "reflected" && s != "transmitted"))
      fail("side", "expected \"reflected\" (the lit side) or \"transmitted\" (the far side)");
    transmitted = s == "transmitted";
    if (transmitted && !thickness_mm) fail("side", "\"transmitted\" needs the sample's thickness_mm");
  }
}

}  // namespace lucent::acquire::detail
