// Tests of render/core/environment.cpp: lat-long conventions, loading, and the importance-sampled
// directional lights (Dal Corso 2014 §4.4, §5.5.3).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/environment.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lucent-env-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

EnvironmentMap constant_map(int w, int h, float value) {
  EnvironmentMap map;
  map.image = imaging::ImageRgb(w, h, value);
  map.source = "constant";
  return map;
}

Vec3f sum_of_radiance(const std::vector<Light>& lights) {
  Vec3f sum = Vec3f::Zero();
  for (const Light& l : lights) sum += l.radiance;
  return sum;
}

TEST(LatLong, DirectionsRoundTripAndFollowTheConvention) {
  EXPECT_TRUE(latlong_direction(0.5f, 0.5f).isApprox(Vec3f(0, 0, -1), 1e-6f));
  EXPECT_TRUE(latlong_direction(0.75f, 0.5f).isApprox(Vec3f(1, 0, 0), 1e-6f));
  EXPECT_NEAR(latlong_direction(0.3f, 0.0f).y(), 1.0f, 1e-6f);
  EXPECT_NEAR(latlong_direction(0.3f, 1.0f).y(), -1.0f, 1e-6f);
  for (float u = 0.01f; u < 1; u += 0.07f) {
    for (float v = 0.02f; v < 1; v += 0.09f) {
      const Vec3f d = latlong_direction(u, v);
      ASSERT_NEAR(d.norm(), 1.0f, 1e-6f);
      const Vec2f uv = latlong_coordinates(d);
      ASSERT_NEAR(uv.x(), u, 1e-5f);
      ASSERT_NEAR(uv.y(), v, 1e-5f);
    }
  }
}

TEST(EnvironmentLookup, ReturnsTheTexelSeenInThatDirection) {
  EnvironmentMap map = constant_map(16, 8, 0.0f);
  map.image.at(12, 4, 1) = 7.0f;  // column 12 of 16: u = 0.78, about +x; row 4 of 8: just below
  const Vec3f at_texel = latlong_direction((12 + 0.5f) / 16, (4 + 0.5f) / 8);
  EXPECT_FLOAT_EQ(environment_lookup(map, at_texel)[1], 7.0f);
  EXPECT_FLOAT_EQ(environment_lookup(map, -at_texel)[1], 0.0f);
  const EnvironmentMap ones = constant_map(5, 3, 1.0f);
  for (const Vec3f& d : {Vec3f(0, 1, 0), Vec3f(0, -1, 0), Vec3f(1, 2, 3), Vec3f(0, 0, 1)}) {
    EXPECT_TRUE(environment_lookup(ones, d).isApprox(Vec3f(1, 1, 1)));
  }
}

TEST(EnvironmentLights, ConstantRadianceSumsToFourPi) {
  for (const auto& [w, h] : {std::pair{64, 32}, std::pair{7, 5}, std::pair{256, 128}}) {
    for (int count : {1, 4, 16, 100}) {
      const auto lights = environment_lights(constant_map(w, h, 1.0f), count, 3);
      ASSERT_EQ(int(lights.size()), count);
      const Vec3f sum = sum_of_radiance(lights);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], 4 * kPi, 0.01 * 4 * kPi) << w << "x" << h;
      for (const Light& l : lights) {
        EXPECT_EQ(l.type, LightType::kDirectional);
        EXPECT_NEAR(l.direction.norm(), 1.0f, 1e-5f);
      }
    }
  }
}

TEST(EnvironmentLights, EstimateIrradiance) {
  // Under a constant sky of radiance 1, any surface gets irradiance pi: sum_k L_k max(0, n . w_k)
  // with stratified directions is close even for 64 lights.
  const auto lights = environment_lights(constant_map(128, 64, 1.0f), 256, 5);
  for (const Vec3f& n :
       {Vec3f(0, 1, 0), Vec3f(1, 0, 0), Vec3f(0, 0, -1), Vec3f(1, 1, 1).normalized()}) {
    double E = 0;
    for (const Light& l : lights) E += l.radiance[0] * std::max(0.0f, n.dot(l.direction));
    EXPECT_NEAR(E, kPi, 0.05 * kPi) << n.transpose();
  }
}

TEST(EnvironmentLights, BrightTexelAttractsTheLights) {
  EnvironmentMap map = constant_map(64, 32, 0.01f);
  const int i = 40, j = 10;
  for (int c = 0; c < 3; ++c) map.image.at(i, j, c) = 1e4f;
  const Vec3f sun = latlong_direction((i + 0.5f) / 64, (j + 0.5f) / 32);
  const auto lights = environment_lights(map, 16, 1);
  int near_sun = 0;
  for (const Light& l : lights) {
    if (l.direction.dot(sun) > std::cos(10 * kPi / 180)) ++near_sun;
  }
  EXPECT_GE(near_sun, 14);
  // The estimate of the total stays right: the map's integral is dominated by the sun texel.
  const double texel_sr = 2 * kPi / 64 * (std::cos(kPi * j / 32) - std::cos(kPi * (j + 1) / 32));
  const double integral = 1e4 * texel_sr + 0.01 * (4 * kPi - texel_sr);
  EXPECT_NEAR(sum_of_radiance(lights)[0], integral, 0.05 * integral);
}

TEST(EnvironmentLights, SameSeedSameLights) {
  const EnvironmentMap map = constant_map(32, 16, 1.0f);
  const auto a = environment_lights(map, 8, 42), b = environment_lights(map, 8, 42);
  const auto c = environment_lights(map, 8, 43);
  ASSERT_EQ(a.size(), b.size());
  bool any_different = false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_TRUE(a[k].direction.isApprox(b[k].direction));
    any_different |= !a[k].direction.isApprox(c[k].direction);
  }
  EXPECT_TRUE(any_different);
}

TEST(EnvironmentLights, BlackMapGivesNoLightsAndBadCountThrows) {
  EXPECT_TRUE(environment_lights(constant_map(8, 4, 0.0f), 16, 1).empty());
  EXPECT_THROW((void)environment_lights(constant_map(8, 4, 1.0f), 0, 1), Error);
}

TEST(LoadEnvironment, ReadsExr) {
  const fs::path path = scratch("sky.exr");
  imaging::ImageRgb image(8, 4, 0.5f);
  image.at(3, 1, 2) = 9.0f;
  imaging::write_exr(path, image);
  const EnvironmentMap map = load_environment(path);
  EXPECT_EQ(map.image.width, 8);
  EXPECT_EQ(map.image.height, 4);
  EXPECT_FLOAT_EQ(map.image.at(3, 1, 2), 9.0f);
  EXPECT_NE(map.to_string().find("8x4"), std::string::npos);
}

TEST(LoadEnvironment, ReadsRadianceHdr) {
  // A flat (not run-length encoded) 4x2 RGBE file: mantissa 128, exponent 129 is 1.0.
  const fs::path path = scratch("sky.hdr");
  {
    std::ofstream out(path, std::ios::binary);
    out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n";
    for (int p = 0; p < 8; ++p) out << char(128) << char(64) << char(32) << char(129);
  }
  const EnvironmentMap map = load_environment(path);
  ASSERT_EQ(map.image.width, 4);
  ASSERT_EQ(map.image.height, 2);
  EXPECT_NEAR(map.image.at(1, 1, 0), 1.0f, 0.01f);
  EXPECT_NEAR(map.image.at(1, 1, 1), 0.5f, 0.01f);
  EXPECT_NEAR(map.image.at(1, 1, 2), 0.25f, 0.01f);
}

TEST(LoadEnvironment, NonImageThrowsNamingTheFile) {
  const fs::path text = scratch("notes.exr");
  std::ofstream(text) << "not an image\n";
  const fs::path hdr = scratch("notes.hdr");
  std::ofstream(hdr) << "not an image either\n";
  const fs::path png = scratch("sky.png");
  std::ofstream(png) << "x";
  for (const fs::path& path : {text, hdr, png, scratch("missing.exr")}) {
    try {
      (void)load_environment(path);
      ADD_FAILURE() << "accepted " << path;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace lucent::render
