// libFuzzer target: the batch manifest reader and the shard-summary merge on arbitrary bytes (a
// manifest written to a temporary file; the same bytes as JSON summaries, one and two shards).
// Every input must end in rows, a merged summary or a lucent::Error.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "batch.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string path = "/tmp/lucent-fuzz-manifest-" + std::to_string(::getpid()) + ".csv";
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    (void)lucent::cli::read_batch_manifest(path);
  } catch (const lucent::Error&) {
  }
  ::unlink(path.c_str());
  try {
    const nlohmann::json doc = lucent::parse_json(bytes, "fuzz.json");
    (void)lucent::cli::merge_batch_summaries({doc}, {"a.json"});
    (void)lucent::cli::merge_batch_summaries({doc, doc}, {"a.json", "b.json"});
  } catch (const lucent::Error&) {
  }
  return 0;
}
