// libFuzzer target: lucent's camera RAW reader (LibRaw underneath, then lucent's quad binning and
// level checks), on arbitrary bytes. Seeds: fuzz/seeds/raw, DNGs written by write_dng for
// tests/imaging/camera_raw_test.cpp (a 48 x 32 RGGB mosaic with EXIF exposure and ISO, and a
// 24 x 24 one without), and tests/imaging/data/libraw_0.20_abort.dng (LibRaw 0.20 aborts on it).
// decode_camera_raw runs LibRaw in a forked child, so libFuzzer's coverage guidance sees lucent's
// side (the answer's parsing, the checks below), not LibRaw's parser: this target holds the
// guarantee users get, that no bytes crash lucent, rather than fuzzing LibRaw.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "lucent/core/error.h"
#include "lucent/imaging/camera_raw.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const lucent::imaging::RawImage image = lucent::imaging::decode_camera_raw(bytes, "fuzz.dng");
    // What the merge relies on: one code per pixel and channel, none above the white level.
    if (image.data.size() != std::size_t(image.width) * image.height * 3) __builtin_trap();
    for (std::uint16_t v : image.data) {
      if (v > image.max_value) __builtin_trap();
    }
  } catch (const lucent::Error&) {
  }
  return 0;
}
