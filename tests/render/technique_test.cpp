// The technique interface (render/include/lucent/render/technique_base.h) and its factory in the
// registry (technique.h): every frame-by-frame technique, driven only through `Technique&`, gives
// the image of its own still renderer bit for bit; the setters keep their contract (the same scene
// again changes nothing, a new material reaches the image, the maps restart); the statistics have
// one form. Skipped without headless OpenGL 4.5.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "gl_fixture.h"
#include "lucent/materials/material.h"
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/technique.h"

namespace lucent::render {
namespace {

class TechniqueTest : public testing_gl::GlTest {
 protected:
  void SetUp() override {
    LUCENT_SKIP_WITHOUT_GL();
    context_->make_current();  // render_still makes contexts of its own
  }

  // 24 px: a 1280-triangle sphere (the tile for fur), one directional and one point light, and
  // each technique's knobs at their smallest (as scripts/identical-renders).
  static Scene scene_for(TechniqueId id) {
    Scene scene;
    scene.mesh = load_mesh(id == TechniqueId::kFur ? "tile" : "sphere:3", 100);
    scene.material = materials::load_material("marble");
    scene.lights = {parse_light("directional:1,0.5,0.5:1,1,1"),
                    parse_light("point:-60,60,80:10000,10000,10000")};
    scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, 24, 24);
    return scene;
  }
  static TechniqueOptions tiny() {
    TechniqueOptions o;
    o.settings.frames = 2;
    o.settings.directions = 4;
    o.settings.samples = 8;
    o.settings.disc_points = 64;
    o.settings.radiance_map_size = 64;
    o.settings.light_map_size = 64;
    o.sh.shadow_map_size = 64;
    o.sh.cube_map_size = 16;
    o.fur.texels = 16;
    o.fur.shells = 8;
    return o;
  }
  // Frames until the technique says it has converged (at most 50).
  static void converge(Technique& t) {
    for (int i = 0; i < 50 && !t.converged(); ++i) t.render_frame();
    ASSERT_TRUE(t.converged()) << technique_info(t.id()).name;
  }
};

TEST(TechniqueRegistry, MakesEveryFrameByFrameTechniqueAndNotTheReference) {
  for (const TechniqueInfo& info : techniques()) {
    // A technique converges frame by frame or renders stills only, never neither: the viewer and
    // render_still rely on one of the two.
    EXPECT_EQ(info.make != nullptr, info.gpu) << info.name;
  }
  EXPECT_THROW(make_technique(TechniqueId::kReference), std::logic_error);
}

TEST_F(TechniqueTest, DrivenThroughTheInterfaceEachGivesItsStillImageBitForBit) {
  for (const TechniqueInfo& info : techniques()) {
    if (info.make == nullptr) continue;
    const Scene scene = scene_for(info.id);
    const TechniqueOptions options = tiny();
    const ImageRgb still = render_still(info.id, scene, options, nullptr);
    context_->make_current();

    std::unique_ptr<Technique> t = make_technique(info.id);
    ASSERT_EQ(t->id(), info.id);
    t->setup(scene, options);
    EXPECT_FALSE(t->converged()) << info.name << ": converged before its first frame";
    converge(*t);
    const ImageRgb image = t->read_image();
    ASSERT_EQ(image.width, 24);
    ASSERT_EQ(image.height, 24);
    EXPECT_EQ(image.data, still.data) << info.name;
    const std::vector<std::uint8_t> mask = t->read_mask();
    ASSERT_EQ(mask.size(), std::size_t(24 * 24)) << info.name;
    int seen = 0;
    for (std::uint8_t m : mask) seen += m;
    EXPECT_GT(seen, 24) << info.name << ": the object covers part of the frame";

    const FrameStats stats = t->frame_stats();
    EXPECT_GE(stats.frames, 1) << info.name;
    ASSERT_FALSE(stats.pass_ms.empty()) << info.name;
    for (const auto& [pass, ms] : stats.pass_ms) {
      EXPECT_TRUE(std::isfinite(ms) && ms >= 0) << info.name << " " << pass << " " << ms;
    }
    EXPECT_NE(t->to_string().find(stats.pass_ms.front().first), std::string::npos)
        << t->to_string();
  }
}

TEST_F(TechniqueTest, TheSettersKeepTheirContract) {
  for (const TechniqueInfo& info : techniques()) {
    if (info.make == nullptr) continue;
    Scene scene = scene_for(info.id);
    std::unique_ptr<Technique> t = make_technique(info.id);
    t->setup(scene, tiny());
    converge(*t);
    const ImageRgb before = t->read_image();

    // The same material and camera again: the same image, and the hierarchical links stand.
    long links = 0;
    if (info.id == TechniqueId::kHierarchical) {
      links = static_cast<HierarchicalRenderer&>(*t).stats().links;
    }
    t->set_material(scene.material);
    t->set_camera(scene.camera);
    converge(*t);
    t->render_frame();
    EXPECT_EQ(t->read_image().data, before.data) << info.name;
    if (info.id == TechniqueId::kHierarchical) {
      const hierarchical::Stats& s = static_cast<HierarchicalRenderer&>(*t).stats();
      EXPECT_EQ(s.links, links);
      EXPECT_EQ(s.form_factor_calls, 0) << "the same material re-linked";
    }

    // Another material reaches the image (fur's hairs and skin included).
    scene.material = materials::load_material("ketchup");
    t->set_material(scene.material);
    if (info.frame_snapshots) {
      EXPECT_FALSE(t->converged()) << info.name << ": a new material restarts accumulation";
    }
    converge(*t);
    t->render_frame();
    EXPECT_NE(t->read_image().data, before.data) << info.name << ": the material was ignored";
  }
}

}  // namespace
}  // namespace lucent::render
