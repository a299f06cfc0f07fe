// The viewer's techniques (see viewer.h): the switch, a frame of the current frame-by-frame
// technique (technique_base.h), the reference's image on screen, and the difference view of the
// current technique against the cached reference.
#include "viewer_impl.h"

namespace lucent::render::viewer_detail {

void Viewer::set_technique(const std::string& name) {
  set_technique(parse_technique(name, "technique"));
}

void Viewer::set_technique(TechniqueId technique) {
  technique_ = technique;
  // Same scene, another technique: the cached reference stays valid for the difference view.
  const std::uint64_t version = scene_version_;
  apply_camera();  // the maps may render at a reduced resolution, the others at the view's
  scene_changed();
  scene_version_ = version;
}

TechniqueOptions Viewer::technique_options() const {
  TechniqueOptions o;
  o.settings = running_settings();  // the maps at the frame budget's level
  o.maps.time_stages = true;  // the panel shows the passes' times
  // Within a frame budget a level is set up a step a display frame (a level's set-up took 0.2-0.3
  // s on llvmpipe, input unanswered meanwhile); the level below is shown until it has a frame.
  o.maps.staged_setup = frame_budget_ms_ > 0;
  o.sh = options_.sh;
  o.hierarchical = options_.hierarchical;
  o.fur = options_.fur;
  o.reference = options_.reference;
  o.pathtrace = options_.pathtrace;
  o.pathtrace.seed = options_.reference.seed;
  return o;
}

int Viewer::maps_frames() const {
  const Technique* maps = live(TechniqueId::kMaps);
  return maps != nullptr ? maps->frame_stats().frames : 0;
}

void Viewer::sync(LiveTechnique& live) {
  Technique& t = *live.technique;
  const SceneVersions& now = versions_;
  if (live.seen.geometry != now.geometry)
    t.set_geometry(scene_.mesh.positions, scene_.mesh.normals);
  if (live.seen.camera != now.camera) t.set_camera(scene_.camera);
  if (live.seen.lights != now.lights) t.set_lights(scene_.lights);
  if (live.seen.material != now.material) t.set_material(scene_.material);
  live.seen = now;
}

// The current technique: made when first chosen, anew on a new window size where its targets
// cannot change size, and brought up to date with the scene.
Technique& Viewer::current_technique() {
  LiveTechnique& slot = live_[std::size_t(technique_)];
  const Camera& camera = scene_.camera;
  if (slot.technique && !slot.technique->resizable() &&
      (slot.width != camera.width || slot.height != camera.height)) {
    slot.technique.reset();
  }
  if (!slot.technique) {
    std::unique_ptr<Technique> made = make_technique(technique_);
    made->setup(scene_, technique_options());
    slot.technique = std::move(made);
    slot.seen = versions_;
    slot.width = camera.width;
    slot.height = camera.height;
  }
  sync(slot);
  return *slot.technique;
}

void Viewer::draw_technique() {
  Technique* t = nullptr;
  try {
    t = &current_technique();
    if (technique_ == TechniqueId::kFur && fur_lobe_) {
      // Klotzli & Olano's single low-frequency lobe turning about the vertical (key L).
      const double time = glfwGetTime();
      const Eigen::Vector3d world(std::cos(0.8 * time) * 0.7, 0.7, std::sin(0.8 * time) * 0.7);
      const ShVector<double> lobe = sh_lobe(tile_from_world(world.normalized()), 4);
      static_cast<FurRenderer&>(*t).set_light_sh({lobe, lobe, lobe});
      live_[std::size_t(technique_)].seen.lights = ~std::uint64_t(0);  // the scene's at next sync
    }
    // Nothing is rendered once the technique has converged and nothing changed: the last image
    // is presented again (the maps took 17 s a frame, forever, after converging).
    const bool converged = t->converged();
    const bool animated = deformer_ || (technique_ == TechniqueId::kFur && fur_lobe_);
    rendered_last_frame_ = !converged || redraw_ || animated;
    auto* staged =
        technique_ == TechniqueId::kMaps ? dynamic_cast<RadianceMapRenderer*>(t) : nullptr;
    if (rendered_last_frame_ && staged != nullptr && !staged->prepared()) {
      // This display frame's share of the level's set-up.
      if (staged->prepare_step()) level_prepared(*staged);
    } else if (rendered_last_frame_) {
      t->render_frame();
      ++frames_rendered_;
      redraw_ = false;
      if (!converged) budget_after_frame(*t);
      // Converged at a level below the requested settings: on to the next (its first image
      // replaces this one's when it has one).
      if (technique_ == TechniqueId::kMaps && frame_budget_ms_ > 0 && t->converged() &&
          level_ + 1 < int(maps_quality_ladder(settings_, fixed_).size())) {
        switch_maps_level(level_ + 1);
      }
      t = &current_technique();
    }
  } catch (const Error& e) {
    if (technique_ == TechniqueId::kMaps) throw;  // nothing to hand over to
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
    set_technique(TechniqueId::kMaps);  // what runs
    return;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // Converged at the refining resolution: the still at the view's own (one final pass; the
  // radiance maps do not depend on the camera).
  if (technique_ == TechniqueId::kMaps && t->converged() && render_scale_ < 1 && !dragging_) {
    set_render_scale(1);
  }
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (show_difference_) {
    draw_difference();
  } else {
    // A level's first frame not done yet: the level below's converged image, brought to the view.
    Technique* shown = t;
    if (technique_ == TechniqueId::kMaps && t->frame_stats().frames == 0) {
      if (Technique* previous = previous_maps()) {
        LiveTechnique& slot = parked_maps_[std::size_t(level_ - 1)];
        if (slot.seen.camera != versions_.camera) {
          sync(slot);
          previous->render_frame();  // converged: the final pass alone
          glBindFramebuffer(GL_FRAMEBUFFER, 0);
        }
        shown = previous;
      }
    }
    // Auto exposure (a new material or light, E): from the image shown once it has settled a
    // little (converged, or four frames).
    if (auto_exposure_ && (shown->converged() || !technique_info(technique_).frame_snapshots ||
                           shown->frame_stats().frames >= 4)) {
      settings_.exposure = pending_.exposure = auto_exposure(shown->read_image());
      auto_exposure_ = false;
    }
    const ViewRect r = view_rect();
    shown->present(settings_.exposure, r.x, r.y, r.width, r.height);
    if (first_image_s_ == 0 && shown->frame_stats().frames > 0) {
      first_image_s_ =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - options_.started)
              .count();
    }
  }
}

ImageRgb Viewer::technique_image() {
  const Technique* t = live(technique_);
  if (technique_ == TechniqueId::kMaps && t != nullptr && t->frame_stats().frames == 0) {
    // A level still setting up, or before its first frame: the level below is what is shown.
    if (const Technique* previous = previous_maps()) return previous->read_image();
  }
  return t != nullptr ? t->read_image() : live(TechniqueId::kMaps)->read_image();
}

void Viewer::draw_reference() {
  ImageRgb mean;
  int passes = 0;
  if (cpu_worker_->take(mean, passes, reference_error_)) {
    cached_reference_ = mean;
    cached_label_ = technique_info(technique_).name;
    reference_version_ = scene_version_;
    if (auto_exposure_) {
      settings_.exposure = pending_.exposure = auto_exposure(mean);
      auto_exposure_ = false;
    }
    reference_passes_ = passes;
  }
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (reference_passes_ > 0 && !cached_reference_.data.empty()) {
    blit(cached_reference_, settings_.exposure);
  }
}

void Viewer::draw_difference() {
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (reference_version_ != scene_version_ || cached_reference_.data.empty()) {
    difference_text_ =
        "no CPU image of this view: switch to the reference or the path tracer, let it run a "
        "pass, come back";
    const Technique* t = live(technique_);
    const ViewRect r = view_rect();
    (t != nullptr ? t : live(TechniqueId::kMaps))
        ->present(settings_.exposure, r.x, r.y, r.width, r.height);
    return;
  }
  // The technique's image averaged 2 x 2 down to the reference's half resolution.
  const ImageRgb full = technique_image();
  const ImageRgb& ref = cached_reference_;
  ImageRgb small(ref.width, ref.height, 0.0f);
  const int fx = std::max(1, full.width / ref.width), fy = std::max(1, full.height / ref.height);
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x)
      for (int c = 0; c < 3; ++c) {
        float sum = 0;
        for (int j = 0; j < fy; ++j)
          for (int i = 0; i < fx; ++i)
            sum += full.at(std::min(full.width - 1, x * fx + i),
                           std::min(full.height - 1, y * fy + j), c);
        small.at(x, y, c) = sum / float(fx * fy);
      }
  const auto mask = nonzero_mask(ref);
  try {
    const TechniqueInfo& info = technique_info(technique_);
    if (!info.physically_based) {
      // Right only up to a scale: compared after its least-squares scale (image_compare.h).
      const ScaledComparison sc = compare_scaled(small, ref, mask);
      for (float& v : small.data) v *= float(sc.scale);
      difference_text_ = info.name + " after its best scale: " + sc.to_string();
    }
    const ImageDifference d = compare_images(small, ref, mask);
    if (info.physically_based) difference_text_ = d.to_string();
    // (Printed once the image has a frame: the maps set a level up over a few display frames.)
    const bool has_image = !info.frame_snapshots || live(technique_)->frame_stats().frames > 0 ||
                           (technique_ == TechniqueId::kMaps && previous_maps() != nullptr);
    if (!has_image) difference_text_ = info.name + ": no frame yet";
    if (has_image && frames_drawn_ - difference_frame_ >= 30) {
      const std::string frame =
          info.frame_snapshots
              ? " (frame " + std::to_string(live(technique_)->frame_stats().frames) + ")"
              : "";
      std::printf("view: %s%s against the %s (%d passes): %s\n", info.name.c_str(), frame.c_str(),
                  cached_label_.c_str(), reference_passes_, difference_text_.c_str());
      std::fflush(stdout);
      difference_frame_ = frames_drawn_;
    }
    ImageRgb diff(ref.width, ref.height, 0.0f);
    for (std::size_t p = 0; p < mask.size(); ++p)
      for (int c = 0; c < 3; ++c)
        diff.data[3 * p + std::size_t(c)] =
            mask[p] ? float(std::abs(small.data[3 * p + std::size_t(c)] -
                                     ref.data[3 * p + std::size_t(c)]) /
                            d.reference_mean)
                    : 0.0f;
    blit(diff, 10.0f);  // 10 x the relative difference: white is 10% of the mean
  } catch (const Error& e) {
    difference_text_ = e.what();
  }
}

void Viewer::blit(const ImageRgb& mean, float exposure) {
  {
    // Tone-mapped on the CPU with the same curve as the maps' present(), then blitted.
    ToneMapOptions tone;
    tone.exposure = exposure;
    const imaging::RawImage srgb = tone_map(mean, tone);
    std::vector<std::uint8_t> rgb(srgb.data.size());
    const float to_byte = 255.0f / float(srgb.max_value);
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      rgb[i] = std::uint8_t(std::lround(float(srgb.data[i]) * to_byte));
    }
    if (mean.width != reference_w_ || mean.height != reference_h_) {
      if (reference_fbo_ != 0) glDeleteFramebuffers(1, &reference_fbo_);
      if (reference_texture_ != 0) glDeleteTextures(1, &reference_texture_);
      glCreateTextures(GL_TEXTURE_2D, 1, &reference_texture_);
      glTextureStorage2D(reference_texture_, 1, GL_RGBA8, mean.width, mean.height);
      glCreateFramebuffers(1, &reference_fbo_);
      glNamedFramebufferTexture(reference_fbo_, GL_COLOR_ATTACHMENT0, reference_texture_, 0);
      reference_w_ = mean.width;
      reference_h_ = mean.height;
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(reference_texture_, 0, 0, 0, mean.width, mean.height, GL_RGB,
                        GL_UNSIGNED_BYTE, rgb.data());
  }
  if (reference_fbo_ != 0) {
    // Row 0 of the image is the top: flip while blitting.
    const ViewRect r = view_rect();
    glBlitNamedFramebuffer(reference_fbo_, 0, 0, 0, reference_w_, reference_h_, r.x, r.y + r.height,
                           r.x + r.width, r.y, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
}

}  // namespace lucent::render::viewer_detail
