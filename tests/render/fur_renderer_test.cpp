// render/include/lucent/render/fur_renderer.h (Klotzli & Olano on OpenGL): the tile renders finite,
// non-black and deterministic for a seed under every light type; the lights' SH projection.
#include "lucent/render/fur_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "area_light.h"
#include "lucent/core/error.h"
#include "lucent/materials/material.h"
#include "lucent/render/gl_context.h"

namespace lucent::render {
namespace {

TEST(FurLightSh, DirectionalLightIsItsDeltaInTheTileFrame) {
  // A light straight above (world +y) is tile +z: c_i = E Y_i(+z), only the zonal terms.
  const auto c = fur_light_sh({parse_light("directional:0,1,0:2,1,0.5")}, Vec3f::Zero());
  const auto y = sh_basis<double>(0.0, 0.0, 1.0);
  for (int i = 0; i < kShCoefficients; ++i) {
    EXPECT_NEAR(c[0][std::size_t(i)], 2 * y[std::size_t(i)], 1e-6);
    EXPECT_NEAR(c[2][std::size_t(i)], 0.5 * y[std::size_t(i)], 1e-6);
  }
  // A small far rect is a point light of intensity L A cos.
  const auto rect = fur_light_sh({rect_light({0, 500, 0}, {1, 0, 0}, {0, 0, 1}, {1, 1, 1})}, Vec3f::Zero());
  const auto point = fur_light_sh({parse_light("point:0,500,0:4,4,4")}, Vec3f::Zero());
  for (int i = 0; i < kShCoefficients; ++i) EXPECT_NEAR(rect[1][std::size_t(i)], point[1][std::size_t(i)], 1e-9);
}

// Fur over a mesh evaluates the lights' SH in each vertex's frame; that is the rotation of the
// world-frame coefficients (sh_rotate, the sampling method), for every light type, in any frame.
TEST(FurLightSh, VertexFrameEqualsRotatingTheWorldFrameCoefficients) {
  const std::vector<Light> lights = {parse_light("directional:0.3,1,-0.4:1,0.5,0.2"),
                                     parse_light("point:40,80,-30:900,700,500"),
                                     rect_light({-30, 60, 20}, {10, 0, 0}, {0, 3, -8}, {2, 2, 2})};
  const Vec3f centre(5, 20, -3);
  const auto world = fur_light_sh(lights, centre, Eigen::Matrix3d::Identity());
  for (const Vec3f& n :
       {Vec3f(0, 1, 0), Vec3f(0.6f, 0.0f, 0.8f), Vec3f(-0.2f, -0.9f, 0.3883f).normalized(),
        Vec3f(0, 0.99999f, 0.0045f).normalized()}) {
    const Eigen::Matrix3d M = fur_vertex_frame(n);
    EXPECT_NEAR((M * M.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
    EXPECT_NEAR(M.determinant(), 1, 1e-12);  // a rotation, not a reflection
    EXPECT_NEAR((M.row(2).transpose() - n.cast<double>()).norm(), 0, 1e-6);  // local z = n
    const auto local = fur_light_sh(lights, centre, M);
    for (int c = 0; c < 3; ++c) {
      const auto turned = sh_rotate(world[std::size_t(c)], M);
      double peak = 0;
      for (double v : world[std::size_t(c)]) peak = std::max(peak, std::abs(v));
      for (int i = 0; i < kShCoefficients; ++i) {
        EXPECT_NEAR(local[std::size_t(c)][std::size_t(i)], turned[std::size_t(i)], 1e-9 * peak)
            << "coefficient " << i << " channel " << c;
      }
    }
  }
}

TEST(FurRenderer, TileIsFiniteNonBlackAndDeterministic) {
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  std::string why;
  const auto context = GlContext::try_create_headless(&why);
  if (!context) GTEST_SKIP() << "no headless OpenGL: " << why;
  Scene scene;
  scene.mesh = load_mesh("tile", 100);
  scene.material = materials::load_material("skin1");
  scene.camera = orbit_camera(scene.mesh, 30, 40, 2.0f, 48, 48);
  fur::FurOptions o;
  o.texels = 16;
  o.shells = 8;
  o.overcoat.hairs = 40;
  o.undercoat.hairs = 150;
  for (const char* light : {"directional:0.4,1,0.2:1,1,1", "point:30,80,-20:8000,8000,8000",
                            "rect:0,60,0:20,0,0:0,0,20:2,2,2"}) {
    scene.lights = {parse_light(light)};
    const ImageRgb a = render_fur(scene, o), b = render_fur(scene, o);
    double sum = 0;
    for (float v : a.data) {
      ASSERT_TRUE(std::isfinite(v)) << light;
      sum += v;
    }
    EXPECT_GT(sum, 0) << light;
    EXPECT_EQ(a.data, b.data) << light;
  }
  fur::FurOptions other = o;
  other.seed = 7;
  scene.lights = {parse_light("directional:0.4,1,0.2:1,1,1")};
  EXPECT_NE(render_fur(scene, other).data, render_fur(scene, o).data);
  // Any other mesh takes the fur-over-a-mesh path (fur_glsl_twin_test renders it); it still
  // refuses a scene without lights, before any work.
  scene.mesh = load_mesh("sphere:1", 100);
  scene.lights.clear();
  EXPECT_THROW(render_fur(scene, o), Error);
}

}  // namespace
}  // namespace lucent::render
