// Tone mapping and image output of renders (tone_map.h).
#include "lucent/render/tone_map.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"

namespace lucent::render {
namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return e;
}

}  // namespace

float tone_curve(float x) {
  if (!(x > 0)) return 0.0f;  // negative and NaN
  if (std::isinf(x)) return 1.0f;
  return x / (1.0f + x);
}

float srgb_encode(float linear) {
  const float x = std::clamp(std::isnan(linear) ? 0.0f : linear, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float encoded) {
  const float v = std::clamp(std::isnan(encoded) ? 0.0f : encoded, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

imaging::ImageRgb displayed(const imaging::ImageRgb& linear, const ToneMapOptions& options) {
  imaging::ImageRgb out = linear;
  for (float& v : out.data) v = tone_curve(v * options.exposure);
  return out;
}

imaging::ImageRgb displayed(const imaging::RawImage& png) {
  imaging::ImageRgb out(png.width, png.height, 0.0f);
  const float scale = 1.0f / float(png.max_value);
  for (std::size_t i = 0; i < out.data.size(); ++i)
    out.data[i] = srgb_decode(float(png.data[i]) * scale);
  return out;
}

imaging::RawImage tone_map(const imaging::ImageRgb& linear, const ToneMapOptions& options) {
  imaging::RawImage out(linear.width, linear.height, 255);
  for (std::size_t i = 0; i < linear.data.size(); ++i) {
    const float v = srgb_encode(tone_curve(linear.data[i] * options.exposure));
    out.data[i] = static_cast<std::uint16_t>(std::lround(v * 255.0f));
  }
  return out;
}

bool is_render_image_path(const std::filesystem::path& path) {
  const std::string e = lower_extension(path);
  return e == ".png" || e == ".exr";
}

void write_render_image(const std::filesystem::path& path, const imaging::ImageRgb& linear,
                        const ToneMapOptions& options,
                        const std::map<std::string, std::string>& attributes) {
  const std::string e = lower_extension(path);
  if (e == ".exr") {
    imaging::write_exr(path, linear, attributes);
  } else if (e == ".png") {
    imaging::write_png(path, tone_map(linear, options));
  } else {
    throw Error(path.string() + ": output must be .png (tone-mapped) or .exr (linear)");
  }
}

float auto_exposure(const imaging::ImageRgb& linear, const std::vector<std::uint8_t>& mask) {
  std::vector<float> luminance;
  const std::size_t pixels = std::size_t(linear.width) * linear.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    const float y = 0.2126f * linear.data[3 * p] + 0.7152f * linear.data[3 * p + 1] +
                    0.0722f * linear.data[3 * p + 2];
    const bool object = mask.empty() ? y > 0 : mask[p] != 0;
    if (object && std::isfinite(y)) luminance.push_back(y);
  }
  if (luminance.empty()) return 1.0f;
  const std::size_t k =
      std::min(luminance.size() - 1, std::size_t(0.95 * double(luminance.size())));
  std::nth_element(luminance.begin(), luminance.begin() + std::ptrdiff_t(k), luminance.end());
  const float p95 = luminance[k];
  return p95 > 0 ? 2.0f / p95 : 1.0f;
}

}  // namespace lucent::render
