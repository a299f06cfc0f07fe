// Tests of the radiance-map technique (render/techniques/maps/radiance_maps*.cpp,
// render/techniques/maps/shaders/; its CPU sampling is in radiance_maps_sampling_test.cpp): the
// OpenGL pipeline on tiny renders (48-64 px, K = 8
// directions, N = 8-16 samples, 64-texel maps; on llvmpipe a frame costs ~0.1 s): physical sanity,
// linearity, accumulation stopping at T frames, and the error against the CPU reference. The GL
// tests skip themselves where no headless OpenGL 4.5 context can be made.
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

// ---- OpenGL pipeline --------------------------------------------------------------------------

class RadianceMapsTest : public testing_gl::GlTest {
 protected:
  static void SetUpTestSuite() {
    GlTest::SetUpTestSuite();
    if (context_ != nullptr) std::printf("OpenGL: %s\n", context_->describe().c_str());
  }
  void SetUp() override {
    if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  }

  // A 100 mm sphere (bounding-box diagonal) seen from +z at 3 radii, lit from +x.
  static Scene sphere_scene(int size, const std::string& material = "marble") {
    Scene scene;
    scene.mesh = load_mesh("sphere", 100);
    scene.material = materials::load_material(material);
    scene.lights = {parse_light("directional:1,0,0:1,1,1")};
    scene.camera = orbit_camera(scene.mesh, 0, 0, 3, size, size);
    return scene;
  }

  static RenderSettings tiny_settings(int frames = 4) {
    RenderSettings s;
    s.directions = 8;
    s.samples = 16;
    s.disc_points = 1000;
    s.radiance_map_size = 64;
    s.light_map_size = 64;
    s.frames = frames;
    return s;
  }

};


double mean_over(const ImageRgb& image, const std::vector<std::uint8_t>& mask, int x0, int x1) {
  double sum = 0;
  int count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = x0; x < x1; ++x) {
      if (!mask[std::size_t(y) * image.width + x]) continue;
      sum += image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2);
      ++count;
    }
  }
  return count > 0 ? sum / (3 * count) : 0;
}

TEST_F(RadianceMapsTest, SphereIsFiniteNonNegativeAndBrighterOnTheLitSide) {
  for (auto model : {DiffusionModel::kDirectionalDipole, DiffusionModel::kDipole}) {
    RenderSettings settings = tiny_settings();
    settings.model = model;
    const Scene scene = sphere_scene(48);
    RadianceMapRenderer renderer;
    renderer.setup(scene, settings);
    while (renderer.render_frame()) {
    }
    const ImageRgb image = renderer.read_image();
    const std::vector<std::uint8_t> mask = renderer.read_mask();
    ASSERT_EQ(image.width, 48);
    ASSERT_EQ(image.height, 48);
    for (float v : image.data) {
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, 0.0f);
    }
    const int object = int(std::count(mask.begin(), mask.end(), 1));
    EXPECT_GT(object, 700);  // the sphere fills about 40% of the frame at 3 radii
    EXPECT_EQ(mask[0], 0);
    EXPECT_EQ(image.at(0, 0, 1), 0.0f);  // background without an environment: black
    // Light from +x, camera on +z: the right half is lit.
    const double left = mean_over(image, mask, 0, 24), right = mean_over(image, mask, 24, 48);
    EXPECT_GT(right, 3 * left) << materials::to_string(model);
    EXPECT_GT(right, 0.0);
    const RadianceMapStats& stats = renderer.stats();
    EXPECT_EQ(stats.frames, settings.frames);
    EXPECT_LT(stats.uncovered_fraction, 0.02);  // K = 8 covers a sphere
    // What it allocated: its K, W_s, its light, its blur's levels.
    EXPECT_DOUBLE_EQ(stats.memory.total_mib(),
                     maps_memory(settings, 1, radiance_map_levels(settings, -1)).total_mib());
    std::printf("%s: left %.4g right %.4g; %s\n", materials::to_string(model).c_str(), left, right,
                stats.to_string().c_str());
  }
}

TEST_F(RadianceMapsTest, DoublingTheLightDoublesTheImage) {
  Scene scene = sphere_scene(40);
  scene.lights.push_back(parse_light("point:-60,80,90:3000,2000,1000"));
  RenderSettings settings = tiny_settings(2);
  RadianceMapRenderer renderer;
  renderer.setup(scene, settings);
  while (renderer.render_frame()) {
  }
  const ImageRgb once = renderer.read_image();
  for (Light& light : scene.lights) light.radiance *= 2;
  renderer.set_lights(scene.lights);  // restarts the accumulation
  EXPECT_EQ(renderer.accumulated_frames(), 0);
  while (renderer.render_frame()) {
  }
  const ImageRgb twice = renderer.read_image();
  // Same samples, same rotations: exactly linear up to float rounding.
  const float peak = *std::max_element(once.data.begin(), once.data.end());
  ASSERT_GT(peak, 0.0f);
  for (std::size_t i = 0; i < once.data.size(); ++i) {
    ASSERT_NEAR(twice.data[i], 2 * once.data[i], 1e-5f * peak) << "value " << i;
  }
}

// The seed's equal layer weights (--maps-layer-weights equal) reach the final pass: coarse layers
// (K 8, 32 texels) weigh a point's grazing views as much as its facing ones, which moves the image.
TEST_F(RadianceMapsTest, EqualLayerWeightsAreTheSeedsAndChangeTheImage) {
  const Scene scene = sphere_scene(32, "potato");
  RenderSettings settings = tiny_settings(2);
  settings.radiance_map_size = 32;
  ImageRgb images[2];
  for (int equal = 0; equal < 2; ++equal) {
    RadianceMapOptions options;
    options.cos_weighted_layers = equal == 0;
    RadianceMapRenderer renderer;
    renderer.setup(scene, settings, options);
    while (renderer.render_frame()) {
    }
    images[equal] = renderer.read_image();
  }
  double sum_cos = 0, sum_diff = 0;
  for (std::size_t i = 0; i < images[0].data.size(); ++i) {
    ASSERT_TRUE(std::isfinite(images[1].data[i]));
    sum_cos += std::abs(images[0].data[i]);
    sum_diff += std::abs(images[1].data[i] - images[0].data[i]);
  }
  EXPECT_GT(sum_diff, 0.005 * sum_cos);
  EXPECT_LT(sum_diff, 0.5 * sum_cos);  // a change of weights, not of what is gathered
}

TEST_F(RadianceMapsTest, AccumulationStopsAfterTFrames) {
  const Scene scene = sphere_scene(32, "potato");
  const RenderSettings settings = tiny_settings(3);
  RadianceMapRenderer renderer;
  renderer.setup(scene, settings);
  std::vector<ImageRgb> images;
  for (int frame = 1; frame <= 3; ++frame) {
    EXPECT_FALSE(renderer.converged());
    EXPECT_TRUE(renderer.render_frame());
    EXPECT_EQ(renderer.accumulated_frames(), frame);
    images.push_back(renderer.read_image());
  }
  EXPECT_TRUE(renderer.converged());
  EXPECT_NE(images[0].data, images[1].data);  // accumulating changes the image
  for (int extra = 0; extra < 3; ++extra) EXPECT_FALSE(renderer.render_frame());
  EXPECT_EQ(renderer.accumulated_frames(), 3);
  EXPECT_EQ(renderer.read_image().data, images.back().data);  // bit for bit
  // A new camera does not restart (the radiance maps are view independent) ...
  Camera moved = scene.camera;
  moved.eye = Vec3f(0, 40, 100);
  renderer.set_camera(moved);
  EXPECT_FALSE(renderer.render_frame());
  EXPECT_NE(renderer.read_image().data, images.back().data);
  // ... a restart does.
  renderer.restart();
  EXPECT_TRUE(renderer.render_frame());
  EXPECT_EQ(renderer.accumulated_frames(), 1);
}

// The maps against the CPU reference (probes, 2048 per pixel: ~1.5% per-pixel noise at 40 px),
// for marble, potato and ketchup under one directional light, one point light and both, on a
// sphere and on the coarsest dragon (40 px, K = 8, W_s = W_l = 64, N = 16 of M = 256, T = 16).
// The bounds are the targets for the light settings (relative RMSE 8%, channel means 3%;
// ketchup 10%), not measurements: at these smaller maps the measured errors are well inside them
// (see the printout), so a regression in the weights, visibility or blur fails them.
//
// The seed's own disc (DiscDistribution::kExponential with DiscSelection::kNearest, M = 1000):
// the N = 16 points nearest x_o stand for a disc of only rho = 2-3 mm and miss the profile beyond
// it, so its image is 0.3-0.8 of the reference's mean, worst in the channel that scatters
// farthest: the test documents that bias, it does not excuse it.
struct AccuracyCase {
  const char* material;
  double rmse_bound, mean_bound;  // relative RMSE; |channel mean ratio - 1|
};

void check_accuracy_against_reference(const std::string& mesh, int map_size,
                                      const std::vector<AccuracyCase>& cases) {
  for (const AccuracyCase& c : cases) {
    for (const std::string lights : {"directional", "point", "both"}) {
      Scene scene;
      scene.mesh = load_mesh(mesh, 100);
      scene.material = materials::load_material(c.material);
      scene.specular = false;  // the subsurface term: the specular lobe is the same in both
      if (lights != "point") scene.lights.push_back(parse_light("directional:1,0.5,0.5:1,1,1"));
      if (lights != "directional")
        scene.lights.push_back(parse_light("point:-60,60,80:5000,5000,5000"));
      scene.camera = orbit_camera(scene.mesh, 0, 0, 3.4f, 40, 40);
      ReferenceOptions reference_options;
      reference_options.pixel_samples = 2048;
      reference_options.threads = 2;
      const ReferenceImage reference =
          render_reference(scene, DiffusionModel::kDirectionalDipole, reference_options);
      const double mean = masked_mean(reference.image, reference.mask);
      ASSERT_GT(mean, 0.0);
      const auto error = [&](const ImageRgb& image) {
        return masked_rmse(image, reference.image, reference.mask) / mean;
      };
      const auto worst_channel_ratio = [&](const ImageRgb& image) {
        const ImageDifference d = compare_images(image, reference.image, reference.mask);
        double worst = 0;
        for (double r : d.mean_ratio) worst = std::max(worst, std::abs(r - 1));
        return worst;
      };

      RenderSettings settings;
      settings.directions = 8;
      settings.samples = 16;
      settings.radiance_map_size = map_size;
      settings.light_map_size = map_size;

      // The seed's N nearest of M exponentially biased points.
      settings.disc_distribution = DiscDistribution::kExponential;
      settings.disc_selection = DiscSelection::kNearest;
      settings.disc_points = 1000;
      settings.frames = 4;
      RadianceMapRenderer nearest;
      nearest.setup(scene, settings);
      while (nearest.render_frame()) {
      }
      const ImageRgb nearest_image = nearest.read_image();
      const double nearest_ratio = masked_mean(nearest_image, reference.mask) / mean;

      // lucent's default disc: the profile's own, in strata.
      settings.disc_distribution = DiscDistribution::kProfile;
      settings.disc_selection = DiscSelection::kStrata;
      settings.disc_points = 256;
      settings.frames = 16;
      RadianceMapRenderer strata;
      strata.setup(scene, settings);
      while (strata.render_frame()) {
      }
      const ImageRgb image = strata.read_image();
      const double last = error(image), channel = worst_channel_ratio(image);
      std::printf(
          "%-9s %-8s %-11s relative RMSE %.4f, worst channel mean off by %.4f (seed's nearest: "
          "mean ratio %.3f)\n",
          mesh.c_str(), c.material, lights.c_str(), last, channel, nearest_ratio);
      const std::string what = mesh + " " + c.material + " " + lights;
      EXPECT_LT(last, c.rmse_bound) << what;
      EXPECT_LT(channel, c.mean_bound) << what;
      EXPECT_GT(nearest_ratio, 0.3) << what;
      EXPECT_LT(nearest_ratio, 0.8) << what;
    }
  }
}

// One test per material (ctest runs them side by side; one test of all three took 150 s).
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnASphereMarble) {
  check_accuracy_against_reference("sphere", 64, {{"marble", 0.08, 0.03}});
}
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnASpherePotato) {
  check_accuracy_against_reference("sphere", 64, {{"potato", 0.08, 0.03}});
}
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnASphereKetchup) {
  check_accuracy_against_reference("sphere", 64, {{"ketchup", 0.10, 0.03}});
}

// The dragon at these tiny sizes (40 px, 128-texel maps: ~0.8 mm texels on 2-4 mm facets):
// measured relative RMSE 0.085-0.15 and channel means within 0.7-5.6% (worst: ketchup under the
// point light, whose perspective light map has the coarsest texels on the object: its green and
// blue means go 0.96, 0.94 -> 0.99, 0.99 with the light map at 512, RMSE 14% -> 13%). The issue's
// targets hold at 64 px with 256-texel maps (faceted_mesh_test: 4.0% and 0.2% for marble under
// both lights; notebooks_data/bench/render_accuracy.md: 3.2-4.8%, ketchup 6.7%, means within
// 1.1%), so these bounds are regression guards for the tiny settings, not the targets. (Before
// the light map kept each texel's triangle normal, marble was 2-3% dark here in every channel.)
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnTheCoarseDragonMarble) {
  check_accuracy_against_reference("dragon:4", 128, {{"marble", 0.18, 0.08}});
}
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnTheCoarseDragonPotato) {
  check_accuracy_against_reference("dragon:4", 128, {{"potato", 0.14, 0.05}});
}
TEST_F(RadianceMapsTest, ErrorAgainstTheCpuReferenceOnTheCoarseDragonKetchup) {
  check_accuracy_against_reference("dragon:4", 128, {{"ketchup", 0.21, 0.11}});
}

// Invariant: a medium that absorbs nothing (sigma_tr = 0: the disc is uniform, sigma* = 0, and the
// profile decays only as a power of r), lit from all six axis directions at once: every pixel is
// finite and non-negative, and the object is lit all round.
TEST_F(RadianceMapsTest, ZeroAbsorptionLitFromEverySideIsFiniteAndNonNegative) {
  for (auto model : {DiffusionModel::kDirectionalDipole, DiffusionModel::kDipole}) {
    Scene scene = sphere_scene(32);
    scene.material.sigma_a = {0, 0, 0};
    scene.material.sigma_s.reset();
    scene.material.g.reset();
    scene.lights.clear();
    for (const char* d : {"1,0,0", "-1,0,0", "0,1,0", "0,-1,0", "0,0,1", "0,0,-1"}) {
      scene.lights.push_back(parse_light(std::string("directional:") + d + ":1,1,1"));
    }
    RenderSettings settings = tiny_settings(4);
    settings.model = model;
    RadianceMapRenderer renderer;
    renderer.setup(scene, settings);
    EXPECT_EQ(renderer.stats().sigma_star_per_mm, 0.0);
    while (renderer.render_frame()) {
    }
    const ImageRgb image = renderer.read_image();
    const std::vector<std::uint8_t> mask = renderer.read_mask();
    long object = 0, dark = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          const float v = image.at(x, y, c);
          ASSERT_TRUE(std::isfinite(v)) << x << "," << y;
          ASSERT_GE(v, 0.0f) << x << "," << y;
        }
        if (!mask[std::size_t(y) * image.width + x]) continue;
        ++object;
        if (image.at(x, y, 1) <= 0) ++dark;
      }
    }
    EXPECT_GT(object, 300);
    EXPECT_LT(dark, object / 50) << materials::to_string(model);  // lit from every side
  }
}

// Invariant: turning the mesh, the light and the camera together leaves the image unchanged up to
// sampling (the K radiance-map directions stay fixed in the world, so the turned mesh is sampled
// by other texels). Dragon:4 turned 90 degrees about y, converged strata maps: measured relative
// RMSE between the two images 0.215 (potato: two independent samplings of one scene; the maps'
// error against the reference on this mesh is 0.21-0.24); bound 0.3. The same turn with the light
// left behind must differ by at least twice the bound (it shows the test can see a light or layer
// direction that does not turn with the scene).
TEST_F(RadianceMapsTest, TurningMeshLightAndCameraTogetherKeepsTheImage) {
  Scene scene;
  scene.mesh = load_mesh("dragon:4", 100);
  scene.material = materials::load_material("potato");
  scene.lights = {parse_light("directional:1,0.6,0.4:1,1,1")};
  scene.camera = orbit_camera(scene.mesh, 20, 15, 3.4f, 48, 48);
  RenderSettings settings = tiny_settings(16);
  settings.disc_points = 128;
  const auto render = [&](const Scene& s) {
    RadianceMapRenderer renderer;
    renderer.setup(s, settings);
    while (renderer.render_frame()) {
    }
    return std::make_pair(renderer.read_image(), renderer.read_mask());
  };
  const auto [image, mask] = render(scene);

  const Eigen::Matrix3f turn =
      Eigen::AngleAxisf(std::numbers::pi_v<float> / 2, Vec3f::UnitY()).toRotationMatrix();
  Scene turned = scene;
  for (Vec3f& p : turned.mesh.positions) p = turn * p;
  for (Vec3f& n : turned.mesh.normals) n = turn * n;
  turned.lights[0].direction = turn * scene.lights[0].direction;
  turned.camera.eye = turn * scene.camera.eye;
  turned.camera.target = turn * scene.camera.target;
  turned.camera.up = turn * scene.camera.up;
  const auto [turned_image, turned_mask] = render(turned);

  long same = 0, object = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    object += mask[i];
    same += mask[i] && turned_mask[i];
  }
  EXPECT_GT(same, object * 97 / 100);  // the same silhouette
  const double mean = masked_mean(image, mask);
  const double difference = masked_rmse(turned_image, image, mask) / mean;
  std::printf("turned 90 degrees: relative RMSE %.3f, mean ratio %.3f\n", difference,
              masked_mean(turned_image, mask) / mean);
  EXPECT_LT(difference, 0.3);
  EXPECT_NEAR(masked_mean(turned_image, mask) / mean, 1.0, 0.1);

  turned.lights = scene.lights;
  const double left_behind = masked_rmse(render(turned).first, image, mask) / mean;
  std::printf("light left behind: relative RMSE %.3f\n", left_behind);
  EXPECT_GT(left_behind, 0.6);
}

// The final pass's environment term: with a uniform white environment the image gains
// F_r(eta, n . w_o) everywhere on the object (exact Fresnel of the material's ior: about 0.04 where
// the surface faces the camera, growing toward the silhouette), and the background shows the map.
TEST_F(RadianceMapsTest, EnvironmentReflectionAddsTheFresnelWeightedMap) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("lucent-env-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  ImageRgb white(32, 16);
  std::fill(white.data.begin(), white.data.end(), 1.0f);
  imaging::write_exr(dir / "white.exr", white);
  Scene scene = sphere_scene(41);
  scene.environment = dir / "white.exr";
  const RenderSettings settings = tiny_settings(2);
  const auto render = [&](bool reflection) {
    RadianceMapOptions options;
    options.environment_reflection = reflection;
    RadianceMapRenderer renderer;
    renderer.setup(scene, settings, options);
    while (renderer.render_frame()) {
    }
    return renderer.read_image();
  };
  const ImageRgb with = render(true), without = render(false);
  // --specular off is the subsurface term alone: no mirror image of the environment either (it
  // was added regardless, +43% in potato's blue against the path tracer).
  scene.specular = false;
  const ImageRgb off_with = render(true), off_without = render(false);
  for (std::size_t i = 0; i < off_with.data.size(); ++i) {
    ASSERT_EQ(off_with.data[i], off_without.data[i]) << i;
  }
  scene.specular = true;
  std::filesystem::remove_all(dir);
  // Background: the map itself (white), with or without the reflection term.
  EXPECT_NEAR(with.at(0, 0, 1), 1.0f, 1e-4f);
  EXPECT_NEAR(without.at(0, 0, 1), 1.0f, 1e-4f);
  // Centre pixel: the camera looks straight at the surface, normal incidence.
  const float eta = float(scene.material.ior);
  const float centre = with.at(20, 20, 1) - without.at(20, 20, 1);
  EXPECT_NEAR(centre, materials::fresnel_reflectance(1.0f, eta), 0.1f * centre);
  // Toward the silhouette the reflection grows (grazing incidence).
  float rim = 0;
  for (int x = 0; x < 20; ++x) {
    const float d = with.at(x, 20, 1) - without.at(x, 20, 1);
    if (without.at(x, 20, 1) != 1.0f) rim = std::max(rim, d);  // object pixels only
  }
  EXPECT_GT(rim, 2 * centre);
  std::printf("environment reflection: centre %.4f (F_r(1, %.2f) = %.4f), rim %.4f\n", centre, eta,
              materials::fresnel_reflectance(1.0f, eta), rim);
  for (std::size_t i = 0; i < with.data.size(); ++i) {
    ASSERT_GE(with.data[i] - without.data[i], -1e-5f) << i;
  }
}

// With the whole disc (N = M) and new radii each frame (RadianceMapOptions::new_radii_each_frame,
// an extension) the gather is an unbiased estimate of the disc integral, and accumulating frames
// does converge toward the reference: marble under one directional light, N = M = 16, measured 1.05
// after one frame and 0.30 after 32 (mean ratio 0.77; the rest is the 32-texel maps' resolution and
// the heavy-tailed e^(sigma* r) weights of the exponential disc). Bound: 32 frames at most 0.7 of
// the first frame's error.
TEST_F(RadianceMapsTest, NewRadiiEachFrameConvergeTowardTheReference) {
  Scene scene = sphere_scene(32, "marble");
  scene.lights = {parse_light("directional:1,0.5,0.5:1,1,1")};
  RenderSettings settings = tiny_settings(32);
  settings.disc_points = settings.samples;
  settings.radiance_map_size = 32;
  ReferenceOptions reference_options;
  reference_options.pixel_samples = 1024;
  reference_options.threads = 2;
  scene.specular = false;
  const ReferenceImage reference = render_reference(scene, settings.model, reference_options);
  const double mean = masked_mean(reference.image, reference.mask);
  // The seed's exponential disc, whose fixed radii this option renews (the profile disc's are
  // already a quadrature of the profile: its first frame is within a few % of the reference).
  settings.disc_distribution = DiscDistribution::kExponential;
  settings.disc_selection = DiscSelection::kNearest;  // N = M: all points, new radii each frame
  RadianceMapOptions options;
  options.new_radii_each_frame = true;
  RadianceMapRenderer renderer;
  renderer.setup(scene, settings, options);
  renderer.render_frame();
  const double first = masked_rmse(renderer.read_image(), reference.image, reference.mask) / mean;
  while (renderer.render_frame()) {
  }
  const double last = masked_rmse(renderer.read_image(), reference.image, reference.mask) / mean;
  const double ratio = masked_mean(renderer.read_image(), reference.mask) / mean;
  std::printf("new radii each frame: relative RMSE 1 frame %.3f, 32 frames %.3f; mean ratio %.3f\n",
              first, last, ratio);
  EXPECT_LT(last, 0.7 * first);
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 1.4);
}

}  // namespace
}  // namespace lucent::render
