// libFuzzer target: the transport-table reader on arbitrary bytes. Every input must end in a table
// or a lucent::Error; a crash, a sanitizer report, an allocation the bytes do not justify (the
// fuzzer's -rss_limit_mb) or another exception type is a finding.
//
// Mutated bytes almost never keep the header's checksum right, which would leave everything behind
// it unfuzzed; so each input is read twice: as it is, and with its header's payload_bytes and crc32
// made to agree with the bytes that follow (a table is checked field by field beyond its checksum).
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "lucent/core/error.h"
#include "lucent/materials/transport_table.h"

namespace {

void read(const std::string& bytes) {
  try {
    (void)lucent::materials::parse_transport_table(bytes, "fuzz.lut");
  } catch (const lucent::Error&) {
  }
}

// The bytes with a header whose size and checksum fit its payload, or "" when the first line is
// not a JSON object.
std::string with_checksum(const std::string& bytes) {
  const std::size_t newline = bytes.find('\n');
  if (newline == std::string::npos) return {};
  nlohmann::json h = nlohmann::json::parse(bytes.substr(0, newline), nullptr, false);
  if (!h.is_object()) return {};
  const std::string payload = bytes.substr(newline + 1);
  h["payload_bytes"] = payload.size();
  h["crc32"] = crc32(0L, reinterpret_cast<const Bytef*>(payload.data()), uInt(payload.size()));
  return h.dump() + "\n" + payload;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  read(bytes);
  if (const std::string fixed = with_checksum(bytes); !fixed.empty()) read(fixed);
  return 0;
}
