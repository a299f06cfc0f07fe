// The hierarchical boundary-element technique on the GPU
// (render/techniques/hierarchical/hierarchical_renderer.cpp,
// render/techniques/hierarchical/shaders/hierarchical.*): against the CPU reference with the same
// R_d (the standard dipole of the chord distance), finiteness and determinism, and a deforming mesh
// and a material change reaching the image. Skipped without headless OpenGL 4.5.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "lucent/materials/material.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "gl_fixture.h"

namespace lucent::render {
namespace {

class HierarchicalRendererTest : public testing_gl::GlTest {
 protected:
  void SetUp() override {
    if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
    context_->make_current();  // render_hierarchical's own context replaced it
  }
  // A 100 mm icosphere of 1280 triangles under a directional and a point light.
  static Scene lit_sphere(const std::string& material, int size) {
    Scene scene;
    scene.mesh = load_mesh("sphere:3", 100);
    scene.material = materials::load_material(material);
    scene.lights = {parse_light("directional:1,0.5,0.5:1,1,1"),
                    parse_light("point:-60,60,80:10000,10000,10000")};
    scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, size, size);
    scene.specular = false;
    return scene;
  }
};

// The check: a lit potato sphere within 10% relative RMSE of the reference. Measured at
// 48 px: potato 1.8%, marble 1.4% (means within 0.9%); the reference's own noise at 1024 probes is ~1.5% (its note), so
// a bound of 10% leaves the technique's error, not the yardstick's, as what fails it.
TEST_F(HierarchicalRendererTest, LitSphereMatchesTheReference) {
  for (const char* material : {"potato", "marble"}) {
    const Scene scene = lit_sphere(material, 48);
    RenderStats stats;
    const ImageRgb image = render_hierarchical(scene, hierarchical::Options{}, &stats);
    ReferenceOptions ro;
    ro.pixel_samples = 1024;
    ro.threads = 2;
    const ReferenceImage reference = render_reference(scene, DiffusionModel::kDipole, ro);
    const ImageDifference d = compare_images(image, reference.image, reference.mask);
    std::printf("%s: %s; %s\n", material, d.to_string().c_str(), stats.details.dump().c_str());
    EXPECT_LT(d.relative_rmse, 0.10) << material;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(d.mean_ratio[std::size_t(c)], 1.0, 0.03) << material << c;
  }
}

TEST_F(HierarchicalRendererTest, FiniteDeterministicDeformableAndMaterialAware) {
  const Scene scene = lit_sphere("skin1", 32);
  HierarchicalRenderer renderer;
  renderer.setup(scene);
  renderer.render_frame();
  const ImageRgb a = renderer.read_image();
  renderer.render_frame();
  const ImageRgb b = renderer.read_image();
  EXPECT_EQ(a.data, b.data);
  for (float v : a.data) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.0f);
  }
  EXPECT_EQ(renderer.stats().form_factor_calls, 0);  // render mode: the links are kept
  auto mean = [](const ImageRgb& im, int c) {
    double s = 0;
    for (std::size_t p = 0; p < im.data.size() / 3; ++p) s += im.data[3 * p + std::size_t(c)];
    return s;
  };
  // Squashed: another shape, and links rebuilt (form factors evaluated again).
  std::vector<Vec3f> moved = scene.mesh.positions;
  for (Vec3f& p : moved) p.y() *= 0.6f;
  Mesh deformed = scene.mesh;
  deformed.positions = moved;
  renderer.set_geometry(moved, area_weighted_normals(deformed));
  renderer.render_frame();
  const ImageRgb c = renderer.read_image();
  EXPECT_GT(renderer.stats().form_factor_calls, 0);
  EXPECT_NE(c.data, a.data);
  // Ketchup: red far above green and blue, unlike skin.
  renderer.set_material(materials::load_material("ketchup"));
  renderer.render_frame();
  const ImageRgb k = renderer.read_image();
  EXPECT_GT(mean(k, 0) / mean(k, 2), 2 * mean(c, 0) / mean(c, 2));
}

}  // namespace
}  // namespace lucent::render
