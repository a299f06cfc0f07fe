// libFuzzer target: lucent's JSON readers (material, capture, profile), on arbitrary bytes.
// Every input must end in a parsed document or a lucent::Error; anything else (a crash, a sanitizer
// report, another exception type) is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "lucent/acquire/capture.h"
#include "lucent/acquire/profile.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/fit/fit_data.h"
#include "lucent/materials/material.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nlohmann::json doc;
  try {
    doc = lucent::parse_json(text, "fuzz.json");
  } catch (const lucent::Error&) {
    return 0;
  }
  try {
    (void)lucent::materials::material_from_json(doc, "fuzz.json");
  } catch (const lucent::Error&) {
  }
  try {
    (void)lucent::acquire::capture_from_json(doc, "fuzz.json", "/nonexistent-fuzz-dir");
  } catch (const lucent::Error&) {
  }
  try {
    (void)lucent::fit::profile_data_from_json(doc, "fuzz.json");
  } catch (const lucent::Error&) {
  }
  return 0;
}
