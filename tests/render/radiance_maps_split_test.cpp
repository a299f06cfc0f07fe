// Work split across calls for the viewer's frame budget: frames (RadianceMapRenderer::set_split),
// whole layers or bands of rows a call, give the image of the unsplit frame, and a partial call
// leaves the last finished image on show; a staged set-up (RadianceMapOptions::staged_setup, a
// step a call) gives the image of the whole one.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "gl_fixture.h"
#include "lucent/materials/material.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

class RadianceMapsSplitTest : public testing_gl::GlTest {
 protected:
  void SetUp() override {
    if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  }
};

Scene sphere_scene() {
  Scene scene;
  scene.mesh = load_mesh("sphere", 60);
  scene.material = materials::load_material("skin1");
  scene.lights = {parse_light("directional:1,0.3,0.6:1,1,1")};
  scene.camera = orbit_camera(scene.mesh, 20, 10, 3, 40, 40);
  return scene;
}

RenderSettings tiny() {
  RenderSettings s;
  s.directions = 6;
  s.samples = 12;
  s.disc_points = 200;
  s.radiance_map_size = 64;
  s.light_map_size = 64;
  s.frames = 3;
  return s;
}

ImageRgb converged_image(RadianceMapRenderer& r, int* calls = nullptr) {
  int n = 0;
  while (r.render_frame()) ++n;
  if (calls) *calls = n;
  return r.read_image();
}

TEST_F(RadianceMapsSplitTest, SplitFramesGiveTheUnsplitImage) {
  const Scene scene = sphere_scene();
  RadianceMapRenderer whole;
  whole.setup(scene, tiny());
  int whole_calls = 0;
  const ImageRgb reference = converged_image(whole, &whole_calls);
  EXPECT_EQ(whole_calls, 3);
  const float peak = *std::max_element(reference.data.begin(), reference.data.end());
  ASSERT_GT(peak, 0.0f);
  struct Split {
    int bands, units, calls;  // calls per accumulated frame: ceil(6 bands / units)
  };
  for (const Split split : {Split{1, 1, 6}, Split{1, 4, 2}, Split{4, 3, 8}, Split{3, 18, 1}}) {
    SCOPED_TRACE(testing::Message() << split.bands << " bands, " << split.units << " a call");
    RadianceMapRenderer r;
    r.setup(scene, tiny());
    r.set_split(split.bands, split.units);
    int calls = 0;
    const ImageRgb image = converged_image(r, &calls);
    EXPECT_EQ(calls, 3 * split.calls);
    EXPECT_EQ(r.accumulated_frames(), 3);
    for (std::size_t i = 0; i < image.data.size(); ++i)
      ASSERT_NEAR(image.data[i], reference.data[i], 1e-5f * peak) << "value " << i;
  }
}

TEST_F(RadianceMapsSplitTest, APartialCallKeepsTheLastFinishedImage) {
  RadianceMapRenderer r;
  r.setup(sphere_scene(), tiny());
  r.set_split(2, 5);  // 12 layer-bands: three calls a frame
  ASSERT_TRUE(r.render_frame());
  ASSERT_TRUE(r.render_frame());
  ASSERT_TRUE(r.render_frame());
  EXPECT_EQ(r.accumulated_frames(), 1);
  EXPECT_FALSE(r.frame_in_progress());
  const ImageRgb first = r.read_image();
  ASSERT_TRUE(r.render_frame());  // a third of frame 2
  EXPECT_TRUE(r.frame_in_progress());
  EXPECT_EQ(r.last_call_units(), 5);
  EXPECT_EQ(r.accumulated_frames(), 1);
  EXPECT_EQ(r.read_image().data, first.data);  // frame 1's image still
  r.restart();
  EXPECT_FALSE(r.frame_in_progress());
  EXPECT_EQ(r.accumulated_frames(), 0);
}

TEST_F(RadianceMapsSplitTest, AStagedSetupGivesTheImageOfTheWholeOne) {
  const Scene scene = sphere_scene();
  RadianceMapRenderer whole;
  whole.setup(scene, tiny());
  const ImageRgb reference = converged_image(whole);
  const float peak = *std::max_element(reference.data.begin(), reference.data.end());
  ASSERT_GT(peak, 0.0f);

  RadianceMapOptions staged;
  staged.staged_setup = true;
  RadianceMapRenderer r;
  r.setup(scene, tiny(), staged);
  EXPECT_FALSE(r.prepared());
  const ImageRgb before = r.read_image();  // nothing rendered yet: black, the camera's size
  ASSERT_EQ(before.width, 40);
  ASSERT_EQ(before.height, 40);
  EXPECT_EQ(*std::max_element(before.data.begin(), before.data.end()), 0.0f);
  int calls = 1;
  while (!r.prepare_step()) ++calls;
  // Mesh and programs, light maps, radiance maps, final target and uniforms; the depth pre-pass
  // in runs of ceil(6 / 4) = 2 layers (3 steps); the warm-up's light map, gather, blur and final.
  EXPECT_EQ(calls, 10);
  EXPECT_TRUE(r.prepared());
  EXPECT_TRUE(r.prepare_step());  // done stays done
  EXPECT_GT(r.stats().depth_pass_ms, 0.0);
  EXPECT_GT(r.stats().warm_up_layer_ms, 0.0);
  EXPECT_GT(r.stats().warm_up_final_ms, 0.0);
  const ImageRgb image = converged_image(r);
  ASSERT_EQ(image.data.size(), reference.data.size());
  for (std::size_t i = 0; i < image.data.size(); ++i)
    ASSERT_NEAR(image.data[i], reference.data[i], 1e-6f * peak) << "value " << i;
}

TEST_F(RadianceMapsSplitTest, AFrameFinishesAStagedSetupAndKeepsTheCameraGivenMeanwhile) {
  Scene scene = sphere_scene();
  RadianceMapOptions staged;
  staged.staged_setup = true;
  RadianceMapRenderer r;
  r.setup(scene, tiny(), staged);
  ASSERT_FALSE(r.prepare_step());  // the mesh and programs only
  // Another view and size before the final target exists: it is built to them.
  scene.camera = orbit_camera(scene.mesh, 70, -5, 3, 30, 20);
  r.set_camera(scene.camera);
  const ImageRgb image = converged_image(r);  // the first frame does the rest of the set-up
  EXPECT_TRUE(r.prepared());
  RadianceMapRenderer whole;
  whole.setup(scene, tiny());
  const ImageRgb reference = converged_image(whole);
  ASSERT_EQ(image.width, 30);
  ASSERT_EQ(image.height, 20);
  const float peak = *std::max_element(reference.data.begin(), reference.data.end());
  ASSERT_GT(peak, 0.0f);
  for (std::size_t i = 0; i < image.data.size(); ++i)
    ASSERT_NEAR(image.data[i], reference.data[i], 1e-6f * peak) << "value " << i;
}

}  // namespace
}  // namespace lucent::render
