// libFuzzer target: the transport-table reader on arbitrary bytes. Every input must end in a table
// or a lucent::Error; a crash, a sanitizer report, an allocation the bytes do not justify (the
// fuzzer's -rss_limit_mb) or another exception type is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "lucent/materials/error.h"
#include "lucent/materials/transport_table.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    (void)lucent::materials::parse_transport_table(bytes, "fuzz.lut");
  } catch (const lucent::Error&) {
  }
  return 0;
}
