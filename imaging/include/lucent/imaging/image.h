// Images as lucent's acquisition code sees them: linear float RGB, or the raw integer pixels of a
// camera bracket. OpenCV and OpenEXR stay behind image_io.h's implementation.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
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

/// What a camera file says about how it was taken (RAW files; PNG/TIFF carry none of it).
struct ExposureMetadata {
  std::optional<double> exposure_s;  ///< exposure time, s
  std::optional<double> iso;         ///< ISO speed
  std::string camera;                ///< make and model, for messages
};

/// A camera bracket as stored: integer code values 0..max_value, RGB. PNG/TIFF: max_value 255 or
/// 65535 and no black level. Camera RAW (camera_raw.h): max_value is the sensor's white level and
/// `black` its per-channel black level, both in codes; linear light is (v - black) / (max - black).
struct RawImage {
  int width = 0;
  int height = 0;
  int max_value =
      255;  ///< the code at which the sensor saturates (255, 65535 or a RAW white level)
  std::array<double, 3> black{0.0, 0.0, 0.0};  ///< code of no light, per channel
  std::vector<std::uint16_t> data;
  ExposureMetadata metadata;

  RawImage() = default;
  RawImage(int w, int h, int max)
      : width(w), height(h), max_value(max), data(std::size_t(w) * h * 3, 0) {}
  std::uint16_t& at(int x, int y, int c) { return data[(std::size_t(y) * width + x) * 3 + c]; }
  std::uint16_t at(int x, int y, int c) const { return data[(std::size_t(y) * width + x) * 3 + c]; }
};

}  // namespace lucent::imaging
