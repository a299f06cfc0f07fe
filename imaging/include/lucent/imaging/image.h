// Images as lucent's acquisition code sees them: linear float RGB, or the raw integer pixels of a
// camera bracket. OpenCV and OpenEXR stay behind image_io.h's implementation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace lucent::imaging {

/// Linear float RGB, row-major, rows along +y; pixel (x, y) channel c at data[(y * width + x) * 3 +
/// c].
struct ImageRgb {
  int width = 0;
  int height = 0;
  std::vector<float> data;

  ImageRgb() = default;
  ImageRgb(int w, int h, float fill = 0.0f)
      : width(w), height(h), data(std::size_t(w) * h * 3, fill) {}
  float& at(int x, int y, int c) { return data[(std::size_t(y) * width + x) * 3 + c]; }
  float at(int x, int y, int c) const { return data[(std::size_t(y) * width + x) * 3 + c]; }
  bool empty() const { return data.empty(); }
};

/// A camera bracket as stored: integer code values 0..max_value (255 or 65535), RGB.
struct RawImage {
  int width = 0;
  int height = 0;
  int max_value = 255;  ///< 255 for 8-bit, 65535 for 16-bit files
  std::vector<std::uint16_t> data;

  RawImage() = default;
  RawImage(int w, int h, int max)
      : width(w), height(h), max_value(max), data(std::size_t(w) * h * 3, 0) {}
  std::uint16_t& at(int x, int y, int c) { return data[(std::size_t(y) * width + x) * 3 + c]; }
  std::uint16_t at(int x, int y, int c) const { return data[(std::size_t(y) * width + x) * 3 + c]; }
};

}  // namespace lucent::imaging
