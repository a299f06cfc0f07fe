#include "lucent/acquire/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lucent/core/error.h"

namespace lucent::acquire {
namespace {

TEST(Camera, SrgbTransferRoundTrips) {
  for (double v = 0.0; v <= 1.0; v += 0.001) EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 1e-12);
  EXPECT_NEAR(srgb_encode(0.0031308), 0.0031308 * 12.92, 1e-12);
  EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-12);
}

TEST(Camera, NoiseFreeExposureIsLinearInRadianceAndTime) {
  CameraOptions o;
  o.noise = false;
  o.response = Response::kLinear;
  o.bits = 16;
  o.black_level_e = 0;
  imaging::ImageRgb radiance(4, 1);
  for (int x = 0; x < 4; ++x) {
    for (int c = 0; c < 3; ++c) radiance.at(x, 0, c) = float(x + 1);
  }
  const double scale = 1000.0;  // electrons per radiance second
  const imaging::RawImage image = expose(radiance, 2.0, scale, o, 0);
  for (int x = 0; x < 4; ++x) {
    const double expected = (x + 1) * 2.0 * scale / o.full_well_e * 65535;
    EXPECT_NEAR(image.at(x, 0, 1), expected, 0.5);
  }
}

TEST(Camera, SaturatesAndQuantisesTo8Bits) {
  CameraOptions o;
  o.noise = false;
  o.bits = 8;
  o.response = Response::kSrgb;
  imaging::ImageRgb radiance(2, 1);
  radiance.at(0, 0, 0) = 1e9f;
  const imaging::RawImage image = expose(radiance, 1.0, 1.0, o, 0);
  EXPECT_EQ(image.max_value, 255);
  EXPECT_EQ(image.at(0, 0, 0), 255);
  // A black pixel reads the black level only.
  EXPECT_EQ(image.at(1, 0, 0), std::lround(srgb_encode(o.black_level_e / o.full_well_e) * 255));
}

TEST(Camera, ShotNoiseHasPoissonVariance) {
  CameraOptions o;
  o.response = Response::kLinear;
  o.read_noise_e = 0;
  o.black_level_e = 0;
  o.full_well_e = 65535;  // one code value per electron
  imaging::ImageRgb radiance(200, 200, 100.0f);
  const imaging::RawImage image = expose(radiance, 1.0, 1.0, o, 3);  // 100 electrons expected
  double sum = 0, sum2 = 0;
  for (auto v : image.data) {
    sum += v;
    sum2 += double(v) * v;
  }
  const double n = double(image.data.size());
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 100.0, 0.2);  // SE of the mean: 10 / sqrt(120000) = 0.03
  EXPECT_NEAR(var, 100.0, 2.0);   // SE of the variance: 100 sqrt(2 / n) = 0.4
}

TEST(Camera, StreamsAreDeterministicAndDistinct) {
  CameraOptions o;
  imaging::ImageRgb radiance(16, 16, 50.0f);
  const imaging::RawImage a = expose(radiance, 1.0, 10.0, o, 1);
  const imaging::RawImage b = expose(radiance, 1.0, 10.0, o, 1);
  const imaging::RawImage c = expose(radiance, 1.0, 10.0, o, 2);
  EXPECT_EQ(a.data, b.data);
  EXPECT_NE(a.data, c.data);
}

TEST(Camera, AutomaticScaleFillsTheWellAtTheShortestExposure) {
  CameraOptions o;
  const double scale = camera_scale(o, 4.0);
  EXPECT_NEAR(4.0 * o.exposures_s.front() * scale, o.auto_fill * (o.full_well_e - o.black_level_e),
              1e-9);
  EXPECT_THROW(camera_scale(o, 0.0), Error);
}

}  // namespace
}  // namespace lucent::acquire
