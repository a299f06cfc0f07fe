// The viewer's techniques (see viewer.h): the switch, the sh renderer's frame, the reference's
// image on screen, and the difference view of the current technique against the cached reference.
#include "viewer_impl.h"

namespace lucent::render::viewer_detail {

void Viewer::set_technique(const std::string& name) {
  set_technique(parse_technique(name, "technique"));
}

void Viewer::set_technique(TechniqueId technique) {
  technique_ = technique;
  // Same scene, another technique: the cached reference stays valid for the difference view.
  const std::uint64_t version = scene_version_;
  scene_changed();
  scene_version_ = version;
}

namespace {

// Makes `renderer` on first use and anew on a new window size (its targets have the camera's
// size), and sends it the mesh when that changed since it last had it. Returns true when made.
template <class Renderer, class Options>
bool keep_current(std::unique_ptr<Renderer>& renderer, FrameTarget& target, const Scene& scene,
                  const Options& options, std::uint64_t geometry_version) {
  if (renderer && target.width == scene.camera.width && target.height == scene.camera.height) {
    if (target.geometry_version != geometry_version) {
      renderer->set_geometry(scene.mesh.positions, scene.mesh.normals);
      target.geometry_version = geometry_version;
    }
    return false;
  }
  renderer.reset();
  auto made = std::make_unique<Renderer>();
  made->setup(scene, options);
  renderer = std::move(made);
  target = {scene.camera.width, scene.camera.height, geometry_version};
  return true;
}

}  // namespace

// A frame of a technique that fails (a GL error, a scene it refuses) says why and hands over to
// the maps; otherwise its image goes on screen (or the difference view).
void Viewer::draw_technique_frame(const std::function<void()>& frame,
                                  const std::function<ImageRgb()>& image,
                                  const std::function<void()>& present) {
  try {
    frame();
  } catch (const Error& e) {
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
    set_technique(TechniqueId::kMaps);  // what runs
    return;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (auto_exposure_) {
    settings_.exposure = pending_.exposure = auto_exposure(image());
    auto_exposure_ = false;
  }
  if (show_difference_) {
    draw_difference();
  } else {
    present();
  }
}

// The sh renderer keeps nothing between frames but its GL objects: the scene goes in before every
// frame (uniform uploads).
void Viewer::draw_sh() {
  draw_technique_frame(
      [&] {
        keep_current(sh_, sh_target_, scene_, options_.sh, geometry_version_);
        sh_->set_camera(scene_.camera);
        sh_->set_lights(scene_.lights);
        sh_->set_material(scene_.material);
        sh_->render_frame();
      },
      [&] { return sh_->read_image(); },
      [&] { sh_->present(settings_.exposure, width_, height_); });
}

// The hierarchical technique: its hierarchy and links are built on first use (and on a new window
// size); a new material re-links.
void Viewer::draw_hierarchical() {
  draw_technique_frame(
      [&] {
        if (keep_current(hbe_, hbe_target_, scene_, options_.hbe, geometry_version_)) {
          material_version_seen_.clear();
        }
        hbe_->set_camera(scene_.camera);
        hbe_->set_lights(scene_.lights);
        // A new material (library, file or the panel's sliders): compare its coefficients.
        std::string key = std::to_string(scene_.material.ior);
        for (int c = 0; c < 3; ++c) {
          key += " " + std::to_string(scene_.material.sigma_a[std::size_t(c)]) + " " +
                 std::to_string(scene_.material.sigma_s_reduced[std::size_t(c)]);
        }
        if (material_version_seen_ != key) {
          if (!material_version_seen_.empty()) hbe_->set_material(scene_.material);
          material_version_seen_ = key;
        }
        hbe_->render_frame();
        ++hbe_frames_;
      },
      [&] { return hbe_->read_image(); },
      [&] { hbe_->present(settings_.exposure, width_, height_); });
}

// Seed 001's tile: its transfer is built once (and on a new window size); the light each frame:
// the scene's, or the seed's single low-frequency lobe turning about the vertical (key L).
void Viewer::draw_fur() {
  draw_technique_frame(
      [&] {
        keep_current(fur_, fur_target_, scene_, options_.fur, geometry_version_);
        fur_->set_camera(scene_.camera);
        if (fur_lobe_) {
          const double t = glfwGetTime();
          const Eigen::Vector3d world(std::cos(0.8 * t) * 0.7, 0.7, std::sin(0.8 * t) * 0.7);
          const ShVector<double> lobe = sh_lobe(tile_from_world(world.normalized()), 4);
          fur_->set_light_sh({lobe, lobe, lobe});
        } else {
          fur_->set_lights(scene_.lights);
        }
        fur_->render_frame();
        ++fur_frames_;
      },
      [&] { return fur_->read_image(); },
      [&] { fur_->present(settings_.exposure, width_, height_); });
}

ImageRgb Viewer::technique_image() const {
  if (technique_ == TechniqueId::kSh && sh_) return sh_->read_image();
  if (technique_ == TechniqueId::kHierarchical && hbe_) return hbe_->read_image();
  if (technique_ == TechniqueId::kFur && fur_) return fur_->read_image();
  return maps_->read_image();
}

void Viewer::draw_reference() {
  ImageRgb mean;
  int passes = 0;
  if (reference_->take(mean, passes, reference_error_)) {
    cached_reference_ = mean;
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
        "no reference for this view: switch to the CPU reference, let it run a "
        "pass, come back";
    if (technique_ == TechniqueId::kSh) {
      sh_->present(settings_.exposure, width_, height_);
    } else if (technique_ == TechniqueId::kHierarchical) {
      hbe_->present(settings_.exposure, width_, height_);
    } else {
      maps_->present(settings_.exposure, width_, height_);
    }
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
    if (frames_drawn_ - difference_frame_ >= 30) {
      const std::string frame = technique_ == TechniqueId::kMaps
                                    ? " (frame " + std::to_string(maps_->accumulated_frames()) + ")"
                                    : "";
      std::printf("view: %s%s against the reference (%d passes): %s\n", info.name.c_str(),
                  frame.c_str(), reference_passes_, difference_text_.c_str());
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
    glBlitNamedFramebuffer(reference_fbo_, 0, 0, 0, reference_w_, reference_h_, 0, height_, width_,
                           0, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
}

}  // namespace lucent::render::viewer_detail
