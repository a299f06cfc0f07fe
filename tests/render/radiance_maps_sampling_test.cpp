// The radiance maps' CPU side, no OpenGL needed (render/techniques/maps/radiance_maps_sampling.h,
// radiance_maps.h): the Halton directions, the biased disc and its weights, the blur schedule, the
// fitted cameras, and the maps' memory against Dal Corso's Table 5.1. The OpenGL pipeline's tests
// are in radiance_maps_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "gl_fixture.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/material.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {
namespace {

// Dal Corso's Table 5.1: K 16, W_s 512, one light of 512, 193 MB (MiB: 64 a radiance map). Its
// formula gives it; lucent's layout at the same settings (RGBA light maps, a half-float face
// normal, three mip levels counted exactly) counted by hand.
TEST(RadianceMapMemory, TheSeedsTableAndLucentsLayout) {
  EXPECT_NEAR(seed_maps_memory_mib(16, 512, 1, 512), 193.67, 0.01);
  RenderSettings s;
  s.directions = 16;
  s.radiance_map_size = 512;
  s.light_map_size = 512;
  const MapsMemory m = maps_memory(s, 1, 3);
  EXPECT_DOUBLE_EQ(m.radiance_mib, 2 * 64 * (1 + 0.25 + 0.0625));  // two, each 64 with its mips
  EXPECT_DOUBLE_EQ(m.radiance_depth_mib, 16);
  EXPECT_DOUBLE_EQ(m.light_maps_mib, 11);  // 4 + 4 + 2 + 1
  EXPECT_DOUBLE_EQ(m.total_mib(), 195);
  EXPECT_DOUBLE_EQ(maps_memory(s, 3, 3).light_maps_mib, 33);
  EXPECT_EQ(radiance_map_levels(s, 2), 3);
  EXPECT_EQ(radiance_map_levels(s, 0), 1);
  s.radiance_map_size = 2;
  EXPECT_EQ(radiance_map_levels(s, 4), 2);  // no level below one texel
}

TEST(RadianceMapSampling, RadicalInverseIsVanDerCorput) {
  EXPECT_DOUBLE_EQ(detail::radical_inverse(1, 2), 0.5);
  EXPECT_DOUBLE_EQ(detail::radical_inverse(6, 2), 0.375);  // 110 -> 0.011
  EXPECT_DOUBLE_EQ(detail::radical_inverse(3, 3), 1.0 / 9);
  EXPECT_DOUBLE_EQ(detail::radical_inverse(7, 5), 2.0 / 5 + 1.0 / 25);
  EXPECT_DOUBLE_EQ(detail::radical_inverse(0, 7), 0.0);
}

TEST(RadianceMapSampling, HaltonDirectionsAreUnitAndCoverTheSphere) {
  const std::vector<Vec3f> d = detail::halton_sphere_directions(512);
  ASSERT_EQ(d.size(), 512u);
  Vec3f mean = Vec3f::Zero();
  for (const Vec3f& v : d) {
    EXPECT_NEAR(v.norm(), 1.0f, 1e-5f);
    mean += v / 512.0f;
  }
  // Area-uniform: the mean of uniformly spread unit vectors vanishes (low discrepancy: fast).
  EXPECT_LT(mean.norm(), 0.01f);
  // Seed Figure 5.9's first points: n = 1 is (s, t) = (1/2, 1/3): z = -1/3, phi = pi.
  EXPECT_NEAR(d[0].z(), -1.0f / 3, 1e-6f);
  EXPECT_NEAR(d[0].x(), -std::sqrt(8.0f) / 3, 1e-6f);
}

TEST(RadianceMapSampling, DiscWeightsIntegrateTheDiscArea) {
  // Kept points are distributed as e^(-sigma* r) / Z(rho) on the disc of radius rho, so
  // sum_i w_i f(d_i) estimates the integral of f over that disc. A constant (area) and the
  // sampling density itself (exact: e^(-sigma* r) w_i = Z / n) come out right.
  const double sigma = 0.2;  // mm^-1
  // (For the area, sigma* rho must stay moderate: e^(sigma* r) is heavy-tailed, and over a disc of
  // sigma* rho = 20 a few hundred points estimate its area to a factor of 5 only.)
  for (auto [M, N, lights, R] : {std::tuple{1000, 50, 1, 100.0}, std::tuple{400, 400, 1, 15.0},
                                 std::tuple{1000, 64, 3, 100.0}}) {
    const detail::DiscSamples disc = detail::exponential_disc_samples(M, N, sigma, R, lights);
    ASSERT_EQ(int(disc.samples.size()), N);
    ASSERT_EQ(int(disc.light_count.size()), lights);
    const double rho = disc.used_radius_mm;
    const double Z =
        2 * std::numbers::pi / (sigma * sigma) * (1 - std::exp(-sigma * rho) * (1 + sigma * rho));
    for (int l = 0; l < lights; ++l) {
      double area = 0, density = 0;
      for (int i = disc.light_offset[l]; i < disc.light_offset[l] + disc.light_count[l]; ++i) {
        const detail::DiscSample& s = disc.samples[std::size_t(i)];
        const double r = std::hypot(s.x_mm, s.y_mm);
        EXPECT_LE(r, rho * (1 + 1e-6));
        area += s.weight_mm2;
        density += s.weight_mm2 * std::exp(-sigma * r);
      }
      EXPECT_NEAR(density, Z, 1e-5 * Z);
      // The area is the hard case (f = 1 against a density falling by e^(-sigma* rho)): within 10%
      // for a few dozen low-discrepancy points.
      EXPECT_NEAR(area, std::numbers::pi * rho * rho, 0.1 * std::numbers::pi * rho * rho)
          << "M=" << M << " N=" << N << " light " << l;
    }
  }
}

// More lights than disc samples (N = 1 or 2 under 3 to 16 lights): every light still gathers
// a whole disc, and the frame still holds N samples (the GPU buffer holds N: before, each light
// past the N-th appended its own copy and `--maps-samples 1` under the default rig of three
// lights wrote past the buffer and crashed).
TEST(RadianceMapSampling, MoreLightsThanSamplesShareTheFramesSamples) {
  for (auto [M, N, lights] : {std::tuple{1, 1, 3}, std::tuple{2, 2, 16}, std::tuple{64, 2, 5}}) {
    for (const auto selection : {DiscSelection::kStrata, DiscSelection::kNearest}) {
      for (int frame : {1, 2, 7}) {
        const detail::DiscSamples disc = detail::exponential_disc_samples(
            M, N, 0.2, 20.0, lights, Eigen::Vector3d::Zero(), selection, frame);
        ASSERT_EQ(int(disc.samples.size()), N) << M << " " << N << " " << lights;
        ASSERT_EQ(int(disc.light_count.size()), lights);
        for (int l = 0; l < lights; ++l) {
          EXPECT_GE(disc.light_count[l], 1);
          EXPECT_GE(disc.light_offset[l], 0);
          EXPECT_LE(disc.light_offset[l] + disc.light_count[l], N) << "light " << l;
          if (l >= N) {
            // It gathers what light l mod N gathers: the same range of the frame's samples.
            EXPECT_EQ(disc.light_offset[l], disc.light_offset[l % N]);
            EXPECT_EQ(disc.light_count[l], disc.light_count[l % N]);
          }
          if (selection == DiscSelection::kNearest) {
            // Its weights integrate the sampling density over the used disc (as in
            // DiscWeightsIntegrateTheDiscArea).
            const double sigma = 0.2, rho = disc.used_radius_mm;
            const double Z = 2 * std::numbers::pi / (sigma * sigma) *
                             (1 - std::exp(-sigma * rho) * (1 + sigma * rho));
            double density = 0;
            for (int i = disc.light_offset[l]; i < disc.light_offset[l] + disc.light_count[l];
                 ++i) {
              const detail::DiscSample& d = disc.samples[std::size_t(i)];
              density += d.weight_mm2 * std::exp(-sigma * std::hypot(d.x_mm, d.y_mm));
            }
            EXPECT_NEAR(density, Z, 1e-5 * Z) << "light " << l;
          }
        }
      }
    }
  }
}

TEST(RadianceMapSampling, NearestNOfMShrinkTheDisc) {
  // Seed §6.2.2: for the same N, a larger M puts the samples closer to x_o.
  const auto small = detail::exponential_disc_samples(100, 16, 0.1, 100.0, 1);
  const auto large = detail::exponential_disc_samples(1000, 16, 0.1, 100.0, 1);
  EXPECT_LT(large.used_radius_mm, 0.5 * small.used_radius_mm);
  // N = M uses the whole disc.
  EXPECT_DOUBLE_EQ(detail::exponential_disc_samples(50, 50, 0.1, 80.0, 1).used_radius_mm, 80.0);
  // The rejection's radius is capped at 30 / sigma* so that it ends for absorbing media.
  EXPECT_DOUBLE_EQ(detail::exponential_disc_samples(50, 50, 3.0, 100.0, 1).disc_radius_mm, 10.0);
}

TEST(RadianceMapSampling, RejectsNMoreThanM) {
  EXPECT_THROW(detail::exponential_disc_samples(10, 20, 0.1, 100.0, 1), Error);
  EXPECT_THROW(detail::exponential_disc_samples(10, 5, 0.1, 100.0, 0), Error);
}

TEST(RadianceMapSampling, BlurLevelFallsAsFramesAccumulate) {
  EXPECT_EQ(detail::blur_level_for_frame(1, 100, 2), 2);
  EXPECT_EQ(detail::blur_level_for_frame(30, 100, 2), 1);  // log4(100/30) = 0.87
  EXPECT_EQ(detail::blur_level_for_frame(99, 100, 2), 1);
  EXPECT_EQ(detail::blur_level_for_frame(100, 100, 2), 0);
  EXPECT_EQ(detail::blur_level_for_frame(1, 100, 0), 0);
  EXPECT_EQ(detail::blur_level_for_frame(1, 1, 2), 0);
}

TEST(RadianceMapSampling, FittedCamerasContainTheBoundingSphere) {
  const Vec3f centre(1, 2, 3);
  const float radius = 10;
  for (const Vec3f& d : detail::halton_sphere_directions(16)) {
    const auto camera = detail::fitted_orthographic(centre, radius, d);
    for (const Vec3f& p : detail::halton_sphere_directions(64)) {
      const Eigen::Vector4f clip = camera.view_proj * (centre + radius * p).homogeneous();
      EXPECT_LE(clip.head<3>().cwiseAbs().maxCoeff(), 1.0f);
    }
  }
  const auto light = detail::fitted_perspective(centre, radius, centre + Vec3f(0, 0, 40));
  for (const Vec3f& p : detail::halton_sphere_directions(64)) {
    const Eigen::Vector4f clip = light.view_proj * (centre + radius * p).homogeneous();
    EXPECT_GT(clip.w(), 0);
    EXPECT_LE((clip.head<3>() / clip.w()).cwiseAbs().maxCoeff(), 1.0f);
  }
}

}  // namespace
}  // namespace lucent::render
