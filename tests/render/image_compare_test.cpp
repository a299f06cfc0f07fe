// lucent compare's measures (render/core/image_compare.cpp): the per-pixel relative RMSE and the
// 4x4-block one, which a converged image's per-pixel noise does not reach.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "lucent/render/image_compare.h"

namespace lucent::render {
namespace {

TEST(ImageCompare, BlocksAverageOutPixelNoiseButNotABias) {
  const ImageRgb reference(16, 16, 2.0f);
  ImageRgb noisy = reference, biased = reference;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      for (int c = 0; c < 3; ++c) {
        noisy.at(x, y, c) = (x + y) % 2 == 0 ? 2.2f : 1.8f;  // +-10%, zero mean in every block
        biased.at(x, y, c) = 2.2f;                           // +10% everywhere
      }
    }
  }
  const std::vector<std::uint8_t> all(16 * 16, 1);
  const ImageDifference n = compare_images(noisy, reference, all);
  EXPECT_NEAR(n.relative_rmse, 0.1, 1e-6);
  EXPECT_EQ(n.blocks, 16u);
  EXPECT_NEAR(n.block_relative_rmse, 0.0, 1e-6);
  const ImageDifference b = compare_images(biased, reference, all);
  EXPECT_NEAR(b.relative_rmse, 0.1, 1e-6);
  EXPECT_NEAR(b.block_relative_rmse, 0.1, 1e-6);
}

TEST(ImageCompare, OnlyBlocksWhollyInsideTheMaskCount) {
  ImageRgb reference(8, 8, 1.0f), image(8, 8, 1.0f);
  std::vector<std::uint8_t> mask(64, 0);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 6; ++x) mask[std::size_t(y * 8 + x)] = 1;  // one whole block, one half
  }
  image.at(5, 0, 1) = 3.0f;  // in the half block only: seen per pixel, not in the blocks
  const ImageDifference d = compare_images(image, reference, mask);
  EXPECT_EQ(d.blocks, 1u);
  EXPECT_GT(d.relative_rmse, 0.1);
  EXPECT_EQ(d.block_relative_rmse, 0.0);
  // No whole block: none reported.
  const ImageDifference none =
      compare_images(ImageRgb(3, 3, 1.0f), ImageRgb(3, 3, 1.0f), std::vector<std::uint8_t>(9, 1));
  EXPECT_EQ(none.blocks, 0u);
}

}  // namespace
}  // namespace lucent::render
