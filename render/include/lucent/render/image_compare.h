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
  /// The same over 4x4 blocks of pixels (each block's mean per channel) lying wholly inside the
  /// mask, relative to the reference's mean over them: the error at a scale where a converged
  /// image's per-pixel noise averages out (0 and no blocks when the mask holds none).
  std::size_t blocks = 0;
  double block_relative_rmse = 0;
  std::string to_string() const;
};

/// Root-mean-square difference over the pixels where mask != 0, all three channels.
double masked_rmse(const ImageRgb& a, const ImageRgb& b, const std::vector<std::uint8_t>& mask);

/// Mean over the pixels where mask != 0, all three channels.
double masked_mean(const ImageRgb& image, const std::vector<std::uint8_t>& mask);

/// Pixels where the reference is non-zero in some channel (a black background is not the object).
std::vector<std::uint8_t> nonzero_mask(const ImageRgb& reference);

/// Throws lucent::Error when the sizes differ or the mask is empty.
ImageDifference compare_images(const ImageRgb& image, const ImageRgb& reference,
                               const std::vector<std::uint8_t>& mask);

/// A render that is right only up to a scale (`--technique sh`, not physically based) against a
/// reference: the least-squares scale s minimising sum (s image - reference)^2 over the mask's
/// pixels and channels, the relative RMSE of s image (as compare_images), and Pearson's
/// correlation of the image's and the reference's values, which no scale changes.
struct ScaledComparison {
  std::size_t pixels = 0;
  double scale = 0;
  std::array<double, 3> channel_scale{};  ///< the least-squares scale of each channel alone
  double correlation = 0;
  double relative_rmse = 0;  ///< of scale * image
  std::string to_string() const;
};

/// Throws lucent::Error as compare_images, and when the image is zero on the whole mask.
ScaledComparison compare_scaled(const ImageRgb& image, const ImageRgb& reference,
                                const std::vector<std::uint8_t>& mask);

}  // namespace lucent::render
