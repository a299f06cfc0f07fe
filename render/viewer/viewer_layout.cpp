// The viewer's layout and frame budget (viewer_impl.h): where the image goes beside the panel, the
// maps' quality level and resolution chosen from the frames measured (frame_budget.h), and the
// edited material saved.
#include "viewer_impl.h"

#include "lucent/core/atomic_file.h"

namespace lucent::render::viewer_detail {

float Viewer::default_panel_width() const {
  // 24 lines' height of the font: wide enough for a slider and its label; at most 40% of the
  // window.
  const float font = 13.0f * std::clamp(float(height_) / 720.0f, 0.55f, 1.6f);
  return std::min(24.0f * font, 0.4f * float(width_));
}

Viewer::ViewRect Viewer::view_rect() const {
  ViewRect r;
  const int panel = show_ui_ && !panel_collapsed_ ? int(std::lround(panel_width_)) : 0;
  // The image keeps at least a third of the window, whatever the panel's width.
  r.x = std::clamp(panel, 0, std::max(0, width_ - std::max(1, width_ / 3)));
  r.width = std::max(1, width_ - r.x);
  // Folded, the panel is a title bar across the top: the image goes below it.
  const int bar = show_ui_ && panel_collapsed_ ? int(std::ceil(panel_bar_height_)) : 0;
  r.height = std::max(1, height_ - bar);
  return r;
}

RenderSettings Viewer::running_settings() const {
  if (frame_budget_ms_ <= 0) return settings_;
  const std::vector<RenderSettings> ladder = maps_quality_ladder(settings_, fixed_);
  RenderSettings s = ladder[std::size_t(std::clamp(level_, 0, int(ladder.size()) - 1))];
  s.exposure = settings_.exposure;
  return s;
}

void Viewer::mark_explicit(const std::string& knob) {
  if (knob == "maps-frames") fixed_.frames = true;
  if (knob == "maps-directions") fixed_.directions = true;
  if (knob == "maps-samples") fixed_.samples = true;
  if (knob == "maps-radiance-map") fixed_.radiance_map = true;
  if (knob == "maps-light-map") fixed_.light_map = true;
}

void Viewer::apply_camera() {
  const ViewRect r = view_rect();
  const float scale = technique_ == TechniqueId::kMaps ? render_scale_ : 1.0f;
  scene_.camera = view_.camera(scene_.mesh, std::max(1, int(std::lround(r.width * scale))),
                               std::max(1, int(std::lround(r.height * scale))));
  ++versions_.camera;
  redraw_ = true;
}

void Viewer::set_render_scale(float scale) {
  if (scale == render_scale_) return;
  render_scale_ = scale;
  apply_camera();  // the same view (the cached reference stays valid), another size
}

void Viewer::apply_split() {
  auto* maps = dynamic_cast<RadianceMapRenderer*>(live(TechniqueId::kMaps));
  if (maps == nullptr) return;
  // A mesh deforming every frame needs every frame whole (a split frame would never finish).
  if (frame_budget_ms_ <= 0 || deformer_) {
    split_ = FrameSplit{};
    maps->set_split(1, 0);
    return;
  }
  const RenderSettings s = running_settings();
  // Before a frame of this level has been measured: the last level's measure in proportion to
  // the work, or, at the very start, a guess of a millisecond per 100,000 gathers (llvmpipe's
  // order; a GPU is measured within a frame and the split relaxed). A staged level replaces
  // this with its warm-up's times once set up (level_prepared).
  double layer_ms = layer_ms_ > 0
                        ? predict_layer_ms(layer_ms_, measured_at_, s)
                        : 1e-5 * double(s.radiance_map_size) * s.radiance_map_size * s.samples;
  split_ = plan_split(layer_ms, s.directions, final_ms_, frame_budget_ms_);
  maps->set_split(split_.bands, split_.units_per_call);
}

void Viewer::switch_maps_level(int level) {
  LiveTechnique& slot = live_[std::size_t(TechniqueId::kMaps)];
  if (level == level_ && slot.technique) return;
  const int levels = int(maps_quality_ladder(settings_, fixed_).size());
  level = std::clamp(level, 0, levels - 1);
  if (int(parked_maps_.size()) < levels) parked_maps_.resize(std::size_t(levels));
  parked_maps_[std::size_t(level_)] = std::move(slot);
  level_ = level;
  if (parked_maps_[std::size_t(level)].technique) {
    slot = std::move(parked_maps_[std::size_t(level)]);
    apply_split();
    redraw_ = true;
  } else {
    rebuild_maps(false);
  }
}

Technique* Viewer::previous_maps() {
  if (level_ == 0 || std::size_t(level_ - 1) >= parked_maps_.size()) return nullptr;
  LiveTechnique& previous = parked_maps_[std::size_t(level_ - 1)];
  return previous.technique && previous.technique->converged() ? previous.technique.get() : nullptr;
}

// After a maps call that accumulated: measure it (a layer's radiance-map pass, the final pass when
// it ended a frame), split the next calls to fit the budget, and lower the resolution while the
// final pass alone takes over 40% of it.
void Viewer::budget_after_frame(Technique& t) {
  if (frame_budget_ms_ <= 0 || technique_ != TechniqueId::kMaps) return;
  auto* maps = dynamic_cast<RadianceMapRenderer*>(&t);
  if (maps == nullptr) return;
  double radiance_ms = 0, final_ms = 0;
  for (const auto& [name, ms] : t.frame_stats().pass_ms) {
    if (name == "radiance map") radiance_ms = ms;
    if (name == "final") final_ms = ms;
  }
  const RenderSettings s = running_settings();
  const int units = maps->last_call_units();
  if (units > 0) {
    // The layer's time from this call's share of it (its units are layers times bands).
    const double layer = radiance_ms / units * double(split_.bands);
    const bool same_level =
        measured_at_.radiance_map_size == s.radiance_map_size && measured_at_.samples == s.samples;
    layer_ms_ =
        layer_ms_ > 0 && same_level && !layer_ms_prior_ ? 0.7 * layer_ms_ + 0.3 * layer : layer;
    layer_ms_prior_ = false;
    measured_at_ = s;
  }
  if (!maps->frame_in_progress())
    final_ms_ = final_ms_ > 0 ? 0.7 * final_ms_ + 0.3 * final_ms : final_ms;
  fit_to_budget();
}

// A level set up (staged, a step a display frame): until its first call is measured, a layer
// takes the larger of the last level's measure in proportion to the work (it misses the geometry's
// fixed share: 2 layers of the second level took 134 ms where 40 were predicted) and the warm-up's
// (an upper bound: a first draw compiles); the final pass, until measured once, the warm-up's.
void Viewer::level_prepared(const RadianceMapRenderer& maps) {
  const RadianceMapStats& w = maps.stats();
  const RenderSettings s = running_settings();
  const double predicted = layer_ms_ > 0 ? predict_layer_ms(layer_ms_, measured_at_, s) : 0;
  layer_ms_ = std::max(predicted, w.warm_up_layer_ms);
  measured_at_ = s;
  layer_ms_prior_ = true;  // the first measure replaces it
  if (final_ms_ <= 0) final_ms_ = w.warm_up_final_ms;
  fit_to_budget();
}

// The final pass's resolution and the frame's split from the figures so far.
void Viewer::fit_to_budget() {
  // (Not in the difference view: it holds the image against the reference pixel for pixel.) Up
  // again, a step at a time, while it takes under 15% (0.15 / 0.49 < 0.4: no see-saw).
  if (final_ms_ > 0.4 * frame_budget_ms_ && refine_scale_ > 0.3f && !show_difference_) {
    refine_scale_ *= 0.7f;
    final_ms_ *= 0.49;  // the pixels' share of it, roughly
    set_render_scale(refine_scale_);
  } else if (final_ms_ > 0 && final_ms_ < 0.15 * frame_budget_ms_ && refine_scale_ < 1 &&
             !show_difference_) {
    refine_scale_ = std::min(1.0f, refine_scale_ / 0.7f);
    final_ms_ /= 0.49;
    set_render_scale(refine_scale_);
  }
  apply_split();
}

void Viewer::save_material(const std::string& path) {
  try {
    materials::write_material(path, scene_.material);
    commit_pending_outputs();
    message_ = "saved " + path;
    std::printf("view: saved the material %s to %s\n", scene_.material.name.c_str(), path.c_str());
    std::fflush(stdout);
  } catch (const Error& e) {
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
  }
}

}  // namespace lucent::render::viewer_detail
