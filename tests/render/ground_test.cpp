// The ground plane under the object (Scene::ground, the maps' ground.frag): lit, shadowed by the
// object on the side away from the light, and not part of the object's mask.
#include <gtest/gtest.h>

#include <vector>

#include "gl_fixture.h"
#include "lucent/materials/material.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

class GroundTest : public testing_gl::GlTest {
 protected:
  void SetUp() override {
    if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  }
};

struct Frame {
  ImageRgb image;
  std::vector<std::uint8_t> mask;
};

Frame render(const std::string& light, bool ground) {
  Scene scene;
  scene.mesh = load_mesh("sphere:3", 60);
  scene.material = materials::load_material("potato");
  scene.lights = {parse_light(light)};
  if (ground) scene.ground = Vec3f(0.5f, 0.5f, 0.5f);
  scene.camera = orbit_camera(scene.mesh, 0, 35, 4, 64, 64);  // from +z, above the plane
  RenderSettings s;
  s.directions = 6;
  s.samples = 8;
  s.disc_points = 64;
  s.radiance_map_size = 32;
  s.light_map_size = 128;
  s.frames = 1;
  RadianceMapRenderer r;
  r.setup(scene, s);
  while (r.render_frame()) {
  }
  return {r.read_image(), r.read_mask()};
}

// The ground's radiance summed over the lower half of the image, left and right of the centre.
std::pair<double, double> ground_halves(const Frame& f) {
  double left = 0, right = 0;
  for (int y = f.image.height / 2; y < f.image.height; ++y)
    for (int x = 0; x < f.image.width; ++x) {
      if (f.mask[std::size_t(y) * f.image.width + x]) continue;
      const double v = f.image.at(x, y, 0) + f.image.at(x, y, 1) + f.image.at(x, y, 2);
      (x < f.image.width / 2 ? left : right) += v;
    }
  return {left, right};
}

TEST_F(GroundTest, LitShadowedAwayFromTheLightAndOutsideTheMask) {
  const Frame none = render("directional:1,1,0:1,1,1", false);
  const Frame from_right = render("directional:1,1,0:1,1,1", true);
  const Frame from_left = render("directional:-1,1,0:1,1,1", true);
  EXPECT_EQ(from_right.mask, none.mask);  // the ground is not the object
  const auto [nl, nr] = ground_halves(none);
  EXPECT_EQ(nl + nr, 0.0);  // no ground: a black background
  const auto [rl, rr] = ground_halves(from_right);
  const auto [ll, lr] = ground_halves(from_left);
  ASSERT_GT(rl + rr, 0.0);
  // The shadow falls away from the light: the left half darker when lit from the right, and the
  // other way round (without the shadow the halves are mirror images, equal).
  EXPECT_LT(rl, 0.9 * rr);
  EXPECT_LT(lr, 0.9 * ll);
  EXPECT_NEAR(rl + rr, ll + lr, 0.02 * (rl + rr));  // mirror scenes, the same light
  std::printf("ground halves lit from the right %.4g | %.4g, from the left %.4g | %.4g\n", rl, rr,
              ll, lr);
}

}  // namespace
}  // namespace lucent::render
