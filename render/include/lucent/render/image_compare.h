// How far one render is from another (`lucent compare`, the viewer's difference view, the
// accuracy benchmarks): relative RMSE and per-channel mean ratios over the pixels that show the
// object.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lucent/render/render_settings.h"

namespace lucent::render {

struct ImageDifference {
  std::size_t pixels = 0;           ///< compared (mask)
  double relative_rmse = 0;         ///< RMSE over the pixels and channels / the reference's mean
  std::array<double, 3> mean_ratio{};  ///< per channel: mean of the image / mean of the reference
  double reference_mean = 0;        ///< all channels
  std::string to_string() const;
};

/// Pixels where the reference is non-zero in some channel (a black background is not the object).
std::vector<std::uint8_t> nonzero_mask(const ImageRgb& reference);

/// Throws lucent::Error when the sizes differ or the mask is empty.
ImageDifference compare_images(const ImageRgb& image, const ImageRgb& reference,
                               const std::vector<std::uint8_t>& mask);

}  // namespace lucent::render
