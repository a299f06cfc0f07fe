// Image differences (image_compare.h).
#include "lucent/render/image_compare.h"

#include <cmath>
#include <cstdio>

#include "lucent/core/error.h"

namespace lucent::render {

std::string ImageDifference::to_string() const {
  char text[256];
  std::snprintf(text, sizeof text,
                "relative RMSE %.4f over %zu pixels; mean ratio R %.4f G %.4f B %.4f", relative_rmse,
                pixels, mean_ratio[0], mean_ratio[1], mean_ratio[2]);
  std::string s = text;
  if (blocks > 0) {
    std::snprintf(text, sizeof text, "; 4x4 blocks: relative RMSE %.4f over %zu",
                  block_relative_rmse, blocks);
    s += text;
  }
  return s;
}

namespace {

// ImageDifference::blocks and block_relative_rmse: 4x4 blocks wholly inside the mask.
void compare_blocks(const ImageRgb& image, const ImageRgb& reference,
                    const std::vector<std::uint8_t>& mask, ImageDifference& d) {
  constexpr int kBlock = 4;
  double squared = 0, sum_reference = 0;
  for (int by = 0; by + kBlock <= image.height; by += kBlock) {
    for (int bx = 0; bx + kBlock <= image.width; bx += kBlock) {
      std::array<double, 3> a{}, b{};
      bool inside = true;
      for (int y = by; y < by + kBlock && inside; ++y) {
        for (int x = bx; x < bx + kBlock; ++x) {
          const std::size_t p = std::size_t(y) * std::size_t(image.width) + std::size_t(x);
          if (!mask[p]) {
            inside = false;
            break;
          }
          for (int c = 0; c < 3; ++c) {
            a[std::size_t(c)] += image.data[3 * p + std::size_t(c)];
            b[std::size_t(c)] += reference.data[3 * p + std::size_t(c)];
          }
        }
      }
      if (!inside) continue;
      ++d.blocks;
      for (int c = 0; c < 3; ++c) {
        const double difference = (a[std::size_t(c)] - b[std::size_t(c)]) / (kBlock * kBlock);
        squared += difference * difference;
        sum_reference += b[std::size_t(c)] / (kBlock * kBlock);
      }
    }
  }
  if (d.blocks == 0 || !(sum_reference > 0)) {
    d.blocks = 0;
    return;
  }
  const double n = 3.0 * double(d.blocks);
  d.block_relative_rmse = std::sqrt(squared / n) / (sum_reference / n);
}

}  // namespace

std::vector<std::uint8_t> nonzero_mask(const ImageRgb& reference) {
  std::vector<std::uint8_t> mask(std::size_t(reference.width) * reference.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p) {
    for (int c = 0; c < 3; ++c) mask[p] |= reference.data[3 * p + std::size_t(c)] != 0.0f;
  }
  return mask;
}

ImageDifference compare_images(const ImageRgb& image, const ImageRgb& reference,
                               const std::vector<std::uint8_t>& mask) {
  if (image.width != reference.width || image.height != reference.height) {
    throw Error("compare: the images differ in size (" + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " against " + std::to_string(reference.width) +
                "x" + std::to_string(reference.height) + ")");
  }
  if (mask.size() != std::size_t(image.width) * image.height) {
    throw Error("compare: the mask does not match the images");
  }
  ImageDifference d;
  std::array<double, 3> sum_image{}, sum_reference{};
  double squared = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    ++d.pixels;
    for (int c = 0; c < 3; ++c) {
      const double a = image.data[3 * p + std::size_t(c)], b = reference.data[3 * p + std::size_t(c)];
      sum_image[std::size_t(c)] += a;
      sum_reference[std::size_t(c)] += b;
      squared += (a - b) * (a - b);
    }
  }
  if (d.pixels == 0) throw Error("compare: no pixel of the reference shows the object");
  d.reference_mean = (sum_reference[0] + sum_reference[1] + sum_reference[2]) / (3.0 * d.pixels);
  d.relative_rmse = std::sqrt(squared / (3.0 * d.pixels)) / d.reference_mean;
  for (int c = 0; c < 3; ++c) {
    d.mean_ratio[std::size_t(c)] = sum_reference[std::size_t(c)] > 0
                                       ? sum_image[std::size_t(c)] / sum_reference[std::size_t(c)]
                                       : (sum_image[std::size_t(c)] > 0 ? INFINITY : 1.0);
  }
  compare_blocks(image, reference, mask, d);
  return d;
}

std::string ScaledComparison::to_string() const {
  char text[256];
  std::snprintf(text, sizeof text,
                "best scale %.5g (R %.5g G %.5g B %.5g), correlation %.4f, relative RMSE after the "
                "scale %.4f over %zu pixels",
                scale, channel_scale[0], channel_scale[1], channel_scale[2], correlation,
                relative_rmse, pixels);
  return text;
}

ScaledComparison compare_scaled(const ImageRgb& image, const ImageRgb& reference,
                                const std::vector<std::uint8_t>& mask) {
  compare_images(image, reference, mask);  // the size and mask checks
  ScaledComparison r;
  std::array<double, 3> ab{}, aa{};
  double sa = 0, sb = 0, n = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    ++r.pixels;
    for (int c = 0; c < 3; ++c) {
      const double a = image.data[3 * p + std::size_t(c)], b = reference.data[3 * p + std::size_t(c)];
      ab[std::size_t(c)] += a * b;
      aa[std::size_t(c)] += a * a;
      sa += a;
      sb += b;
      n += 1;
    }
  }
  const double sum_aa = aa[0] + aa[1] + aa[2];
  if (!(sum_aa > 0)) throw Error("compare: the image is black where the reference shows the object");
  r.scale = (ab[0] + ab[1] + ab[2]) / sum_aa;
  for (int c = 0; c < 3; ++c) {
    r.channel_scale[std::size_t(c)] = aa[std::size_t(c)] > 0 ? ab[std::size_t(c)] / aa[std::size_t(c)] : 0;
  }
  const double ma = sa / n, mb = sb / n;
  double cov = 0, va = 0, vb = 0, squared = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (int c = 0; c < 3; ++c) {
      const double a = image.data[3 * p + std::size_t(c)], b = reference.data[3 * p + std::size_t(c)];
      cov += (a - ma) * (b - mb);
      va += (a - ma) * (a - ma);
      vb += (b - mb) * (b - mb);
      squared += (r.scale * a - b) * (r.scale * a - b);
    }
  }
  r.correlation = va > 0 && vb > 0 ? cov / std::sqrt(va * vb) : 0;
  r.relative_rmse = mb > 0 ? std::sqrt(squared / n) / mb : INFINITY;
  return r;
}

double masked_rmse(const ImageRgb& a, const ImageRgb& b, const std::vector<std::uint8_t>& mask) {
  if (a.width != b.width || a.height != b.height) {
    throw Error("masked_rmse: images differ in size");
  }
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = double(a.data[3 * p + c]) - b.data[3 * p + c];
      sum += d * d;
      ++count;
    }
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

double masked_mean(const ImageRgb& image, const std::vector<std::uint8_t>& mask) {
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (int c = 0; c < 3; ++c) sum += image.data[3 * p + c];
    count += 3;
  }
  return count ? sum / count : 0.0;
}

}  // namespace lucent::render
