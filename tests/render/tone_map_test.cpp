// Tests of render/core/tone_map.cpp: the curve, sRGB encoding, and atomic PNG / EXR output.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/tone_map.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lucent-tone-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

TEST(ToneCurve, ReinhardPerChannel) {
  EXPECT_FLOAT_EQ(tone_curve(0), 0);
  EXPECT_FLOAT_EQ(tone_curve(1), 0.5f);
  EXPECT_FLOAT_EQ(tone_curve(3), 0.75f);
  EXPECT_FLOAT_EQ(tone_curve(-2), 0);
  EXPECT_FLOAT_EQ(tone_curve(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_FLOAT_EQ(tone_curve(std::numeric_limits<float>::infinity()), 1);
  float previous = 0;
  for (float x = 0.01f; x < 1e4f; x *= 1.5f) {
    const float y = tone_curve(x);
    ASSERT_GT(y, previous);
    ASSERT_LT(y, 1.0f);
    previous = y;
  }
}

TEST(SrgbEncode, MatchesTheStandard) {
  EXPECT_FLOAT_EQ(srgb_encode(0), 0);
  EXPECT_FLOAT_EQ(srgb_encode(1), 1);
  EXPECT_NEAR(srgb_encode(0.0031308f), 0.04045f, 1e-5f);  // where the two pieces meet
  EXPECT_NEAR(srgb_encode(0.18f), 0.4614f, 1e-4f);
  EXPECT_FLOAT_EQ(srgb_encode(2), 1);
}

TEST(ToneMap, ExposureThenCurveThenSrgb) {
  imaging::ImageRgb linear(2, 1, 0.0f);
  linear.at(0, 0, 0) = 0.5f;
  linear.at(1, 0, 1) = 1e6f;
  ToneMapOptions options;
  options.exposure = 2;  // 0.5 -> 1 -> 0.5 -> sRGB 0.7354 -> 188
  const imaging::RawImage out = tone_map(linear, options);
  EXPECT_EQ(out.max_value, 255);
  EXPECT_EQ(out.at(0, 0, 0), 188);
  EXPECT_EQ(out.at(0, 0, 1), 0);
  EXPECT_EQ(out.at(1, 0, 1), 255);
}

TEST(WriteRenderImage, PngAndLinearExr) {
  imaging::ImageRgb linear(4, 3, 0.25f);
  linear.at(2, 1, 0) = 3.0f;
  const fs::path exr = scratch("out.exr"), png = scratch("out.PNG");
  ToneMapOptions options;
  options.exposure = 4;  // must not touch the EXR
  write_render_image(exr, linear, options);
  write_render_image(png, linear, options);
  const imaging::ImageRgb back = imaging::read_exr(exr);
  EXPECT_FLOAT_EQ(back.at(2, 1, 0), 3.0f);
  EXPECT_FLOAT_EQ(back.at(0, 0, 0), 0.25f);
  const imaging::RawImage raw = imaging::read_raw_image(png);
  EXPECT_EQ(raw.width, 4);
  EXPECT_EQ(raw.at(0, 0, 0), 188);  // 0.25 * 4 = 1 -> 0.5 -> 188
}

TEST(WriteRenderImage, OtherExtensionsThrowAndWriteNothing) {
  const fs::path tif = scratch("out.tif");
  EXPECT_THROW(write_render_image(tif, imaging::ImageRgb(2, 2, 1.0f)), Error);
  EXPECT_FALSE(fs::exists(tif));
  EXPECT_TRUE(is_render_image_path("a/b.exr"));
  EXPECT_TRUE(is_render_image_path("b.Png"));
  EXPECT_FALSE(is_render_image_path("b.jpg"));
}

}  // namespace
}  // namespace lucent::render
