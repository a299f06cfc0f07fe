// The CPU techniques within an image budget (render_still_within_budget): their samples split into
// passes of their own seeds, averaged weighted by their samples, give an image no further from the
// one pass of them all than two seeds of that pass are from each other; a budget too small for more
// than the coarse pass stops after it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lucent/materials/material.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/technique.h"

namespace lucent::render {
namespace {

Scene sphere() {
  Scene scene;
  scene.mesh = load_mesh("sphere:2", 30);
  scene.material = materials::load_material("marble");
  scene.lights = {parse_light("directional:0.4,0.5,1:1,1,1")};
  scene.camera = orbit_camera(scene.mesh, 20, 10, 3, 20, 20);
  return scene;
}

TechniqueOptions small_options() {
  TechniqueOptions o;
  o.reference.pixel_samples = 128;
  o.reference.threads = 2;
  o.pathtrace.pixel_samples = 32;
  o.pathtrace.threads = 2;
  return o;
}

std::vector<std::uint8_t> object_mask(const ImageRgb& image) {
  std::vector<std::uint8_t> mask(std::size_t(image.width) * image.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p)
    mask[p] = image.data[3 * p] + image.data[3 * p + 1] + image.data[3 * p + 2] > 0 ? 1 : 0;
  return mask;
}

TEST(StillBudget, PassesOfTheirOwnSeedsAverageToTheOnePassImage) {
  const Scene scene = sphere();
  for (const TechniqueId id : {TechniqueId::kReference, TechniqueId::kPathtrace}) {
    SCOPED_TRACE(technique_info(id).name);
    TechniqueOptions o = small_options();
    const ImageRgb whole = render_still(id, scene, o, nullptr);
    TechniqueOptions other = o;
    other.reference.seed = other.pathtrace.seed = 77;
    const ImageRgb whole_other_seed = render_still(id, scene, other, nullptr);

    std::vector<int> images_at;
    RenderStats stats;
    const BudgetedStill b = render_still_within_budget(
        id, scene, o, std::numeric_limits<double>::infinity(),
        [&](const ImageRgb& image, int pass, int samples) {
          EXPECT_EQ(pass, int(images_at.size()));
          EXPECT_EQ(image.width, 20);
          images_at.push_back(samples);
        },
        {}, &stats);
    const int requested = id == TechniqueId::kReference ? 128 : 32;
    EXPECT_EQ(b.requested, requested);
    EXPECT_EQ(b.run.samples, requested);
    const int coarse = std::max(1, requested / 64);
    EXPECT_EQ(b.run.pass_samples, (std::vector<int>{coarse, requested - coarse}));
    EXPECT_EQ(images_at, (std::vector<int>{coarse, requested}));
    EXPECT_FALSE(stats.pass_ms.empty());

    const auto mask = object_mask(whole);
    const ImageDifference seeds = compare_images(whole_other_seed, whole, mask);
    const ImageDifference split = compare_images(b.image, whole, mask);
    ASSERT_GT(seeds.pixels, 100u);
    // Both differences are two independent estimates' noise: the same size, up to the noise of
    // the RMSE itself over ~250 pixels x 3 channels (a few percent; 1.3x is far outside it).
    EXPECT_LT(split.relative_rmse, 1.3 * seeds.relative_rmse) << split.to_string();
    EXPECT_GT(split.relative_rmse, 0.7 * seeds.relative_rmse) << split.to_string();
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(split.mean_ratio[std::size_t(c)], 1.0, 0.03);
  }
}

TEST(StillBudget, ABudgetSpentByTheCoarsePassStopsThere) {
  const BudgetedStill b = render_still_within_budget(TechniqueId::kPathtrace, sphere(),
                                                     small_options(), 1e-6, {}, {}, nullptr);
  EXPECT_EQ(b.run.pass_samples, std::vector<int>{1});  // 32 / 64, at least one
  EXPECT_EQ(b.image.width, 20);
  EXPECT_THROW(
      render_still_within_budget(TechniqueId::kMaps, sphere(), small_options(), 1, {}, {}, nullptr),
      std::logic_error);
}

}  // namespace
}  // namespace lucent::render
