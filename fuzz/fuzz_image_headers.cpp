// libFuzzer target: the image readers' header paths (OpenEXR, PNG/TIFF through OpenCV) on
// arbitrary bytes, written to a temporary file as .exr and as .png. Every input must end in an
// image or a lucent::Error; a header that makes the reader allocate beyond what the bytes justify
// trips the fuzzer's -rss_limit_mb.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"

namespace {

std::string temporary(const char* extension) {
  return "/tmp/lucent-fuzz-image-" + std::to_string(::getpid()) + extension;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* ext : {".exr", ".png"}) {
    const std::string path = temporary(ext);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
      if (std::string(ext) == ".exr")
        (void)lucent::imaging::read_exr(path);
      else
        (void)lucent::imaging::read_raw_image(path);
    } catch (const lucent::Error&) {
    }
    ::unlink(path.c_str());
  }
  return 0;
}
