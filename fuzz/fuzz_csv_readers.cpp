// libFuzzer target: lucent's CSV readers (the radial profile lucent fit reads, the BSSRDF
// configuration table lucent profile reads), on arbitrary bytes.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include "lucent/core/error.h"
#include "lucent/fit/fit_data.h"
#include "lucent/materials/profile_table.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)lucent::fit::parse_profile_csv(text, "fuzz.csv");
  } catch (const lucent::Error&) {
  }
  try {
    std::istringstream in{std::string(text)};
    (void)lucent::materials::read_bssrdf_configs(in, "fuzz.csv");
  } catch (const lucent::Error&) {
  }
  return 0;
}
