// The radiance maps within a time budget per image (radiance_maps.h): run_image_budget
// (frame_budget.h) driving a RadianceMapRenderer per level.
#include <chrono>
#include <memory>

#include "lucent/render/frame_budget.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/radiance_maps.h"
#include "radiance_maps_impl.h"

namespace lucent::render {
namespace {

class MapsLevelRunner final : public BudgetLevelRunner {
 public:
  MapsLevelRunner(const Scene& scene, const RadianceMapOptions& options,
                  const BudgetedMapsOptions& budget)
      : scene_(scene), options_(options), budget_(budget) {}

  void start(const RenderSettings& settings) override {
    renderer_ = std::make_unique<RadianceMapRenderer>();  // one given up is released
    renderer_->setup(scene_, settings, options_);
    settings_ = settings;
  }
  bool frame(MeasuredFrame& m) override {
    const int light_maps = renderer_->stats().light_map_renders;
    if (!renderer_->render_frame()) return false;
    // The light maps only where this frame drew them (point and directional lights: once a level,
    // at its first frame; area lights: every frame).
    const bool drew_light_maps = renderer_->stats().light_map_renders != light_maps;
    for (const auto& [name, ms] : renderer_->frame_stats().pass_ms) {
      if (name == "radiance map") {
        m.radiance_ms = ms;
      } else if (name == "light map") {
        m.light_ms = drew_light_maps ? ms : 0;
      } else {
        m.final_ms += ms;
      }
    }
    return true;
  }
  void level_done(int level, bool refined_next) override {
    done_ = std::move(renderer_);
    done_settings_ = settings_;
    if (refined_next && budget_.on_image) budget_.on_image(done_->read_image(), level);
  }
  /// The last level done (its renderer and settings).
  const RadianceMapRenderer& renderer() const { return *done_; }
  const RenderSettings& settings() const { return done_settings_; }

 private:
  const Scene& scene_;
  const RadianceMapOptions& options_;
  const BudgetedMapsOptions& budget_;
  std::unique_ptr<RadianceMapRenderer> renderer_, done_;
  RenderSettings settings_, done_settings_;
};

}  // namespace

BudgetedMaps render_radiance_maps_within_budget(const Scene& scene,
                                                const RadianceMapOptions& options,
                                                const BudgetedMapsOptions& budget,
                                                RenderStats* stats) {
  const double t0 = now_ms();
  const auto context = GlContext::create_headless();
  MapsLevelRunner runner(scene, options, budget);
  const ImageBudgetRun run = run_image_budget(
      budget.ladder, budget.budget_s, scene.camera.width * scene.camera.height,
      int(scene.lights.size()), [] { return now_ms() / 1000; }, runner, budget.progress);
  BudgetedMaps result;
  result.level = run.level;
  result.levels_run = run.levels_run;
  result.levels_given_up = run.levels_given_up;
  result.level_seconds = run.level_seconds;
  result.requested_frame_ms = run.requested_frame_ms;
  result.image = runner.renderer().read_image();
  if (stats != nullptr) {
    fill_render_stats(runner.renderer(), scene, runner.settings(), options, now_ms() - t0, *stats);
  }
  return result;
}

}  // namespace lucent::render
