// Frames split across calls (RadianceMapRenderer::set_split, the viewer's frame budget): whole
// layers or bands of rows a call give the image of the unsplit frame, and a partial call leaves
// the last finished image on show.
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

}  // namespace
}  // namespace lucent::render
