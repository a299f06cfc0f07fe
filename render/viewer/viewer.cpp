// `lucent view` (see viewer.h): one GLFW window with an OpenGL 4.5 core context, the radiance-map
// renderer drawing into it, Dear ImGui's panel on top, and the CPU reference on a worker thread.
#include "lucent/render/viewer.h"

#include "area_light.h"
#include "viewer_impl.h"

#include "lucent/core/atomic_file.h"

namespace lucent::render {
namespace viewer_detail {

Viewer::Viewer(const ViewerOptions& options)
    : options_(options),
      scene_(options.scene),
      rest_mesh_(options.scene.mesh),
      object_size_mm_(options.object_size_mm),
      settings_(options.settings),
      pending_(options.settings),
      model_from_material_(options.model_follows_material),
      view_(options.view),
      technique_(options.technique),
      material_source_(options.material_source) {
  script_ = parse_script(options.script);
  show_ui_ = !options.hide_panel;
  auto_exposure_ = options.auto_exposure;
  frame_budget_ms_ = options.frame_budget_ms;
  // Within a budget the first frames are at half the view's resolution each way until the final
  // pass is measured (640 x 480 took 100 ms on llvmpipe); measured, the resolution follows it.
  if (frame_budget_ms_ > 0) render_scale_ = refine_scale_ = 0.5f;
  fixed_ = options.fixed;
  settings_.validate();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  window_ = glfwCreateWindow(
      options.scene.camera.width, options.scene.camera.height,
      ("lucent view - " + scene_.material.name + " on " + scene_.mesh.name).c_str(), nullptr,
      nullptr);
  if (window_ == nullptr) {
    throw Error("view: no OpenGL 4.5 core window (" + GlfwSession::last_error() + ")");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  glfwSetWindowUserPointer(window_, this);
  // Installed before ImGui's, which chain to them.
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
    static_cast<Viewer*>(glfwGetWindowUserPointer(w))->scroll_ += float(dy);
  });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS)
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->keys_.push_back(key);
  });
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
  ImGui::StyleColorsDark();
  ImGui::GetStyle().ScaleAllSizes(0.8f);
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 450 core");

  glfwGetFramebufferSize(window_, &width_, &height_);
  // The panel starts beside the image (folded in a small window); its width is known after its
  // first frame, which then re-frames the camera.
  panel_collapsed_ = width_ < 640 || height_ < 480;
  if (show_ui_ && !panel_collapsed_) panel_width_ = default_panel_width();
  const ViewRect r = view_rect();
  scene_.camera = view_.camera(scene_.mesh, r.width, r.height);
  if (std::filesystem::is_regular_file(material_source_)) watcher_ = FileWatcher(material_source_);
  std::snprintf(material_path_.data(), material_path_.size(), "%s", material_source_.c_str());
  if (deform_amplitude_ != options.deform_amplitude) set_deform(options.deform_amplitude);
  rebuild_maps();
  cpu_worker_ = std::make_unique<CpuWorker>();
  if (on_cpu()) scene_changed();
  last_time_ = start_time_ = glfwGetTime();
}

Viewer::~Viewer() {
  cpu_worker_.reset();
  if (reference_fbo_ != 0) glDeleteFramebuffers(1, &reference_fbo_);
  if (reference_texture_ != 0) glDeleteTextures(1, &reference_texture_);
  for (LiveTechnique& t : live_) t.technique.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window_);
}

int Viewer::run() {
  while (!quit_ && !glfwWindowShouldClose(window_)) {
    // Frames as fast as they come while something is to be rendered (the maps accumulate, the
    // resolution comes back after refining, the mesh moves); otherwise nothing is rendered: wake
    // for input, a finished reference pass (the worker needs the CPU more than the window does)
    // and, now and then, to watch the material file.
    const Technique* t = live(technique_);
    const bool busy = !on_cpu() && (t == nullptr || !t->converged() || redraw_ || deformer_ ||
                                    (technique_ == TechniqueId::kMaps && render_scale_ < 1) ||
                                    (auto_exposure_ && !show_difference_) ||
                                    (technique_ == TechniqueId::kFur && fur_lobe_));
    if (busy) {
      glfwPollEvents();
    } else {
      glfwWaitEventsTimeout(script_pos_ < script_.size() || on_cpu() ? 0.05 : 0.5);
    }
    frame();
  }
  const RenderSettings running = running_settings();
  std::printf(
      "view: %ld frames drawn, %ld rendered, %d restarts, %d screenshots; technique %s, "
      "accumulated %d of %d frames\n",
      frames_drawn_, frames_rendered_, restarts_, screenshots_,
      technique_info(technique_).name.c_str(), maps_frames(), running.frames);
  std::printf("view: quality level %d of %d (%s) for a frame budget of %g ms\n", level_ + 1,
              int(maps_quality_ladder(settings_, fixed_).size()), quality_text(running).c_str(),
              frame_budget_ms_);
  // How the window answered: the first image from the command's start, and the frames that
  // rendered after it (input is read once a frame): median, 95th percentile, longest.
  std::vector<double> busy = busy_frame_ms_;
  std::sort(busy.begin(), busy.end());
  const auto at = [&](double q) {
    return busy.empty() ? 0.0
                        : busy[std::min(busy.size() - 1, std::size_t(q * double(busy.size())))];
  };
  std::printf(
      "view: first image after %.2f s; %zu frames rendered after it: median %.0f ms, 95%% "
      "within %.0f ms, longest %.0f ms, %ld over 100 ms\n",
      first_image_s_, busy.size(), at(0.5), at(0.95), busy.empty() ? 0.0 : busy.back(),
      long(std::count_if(busy.begin(), busy.end(), [](double ms) { return ms > 100; })));
  std::printf("view: panel %s, widest line %.0f of %.0f px\n",
              !show_ui_          ? "hidden"
              : panel_collapsed_ ? "folded"
                                 : "open",
              panel_content_width_, panel_inner_width_);
  return 0;
}

void Viewer::frame() {
  const double now = glfwGetTime();
  frame_ms_ = 1000 * (now - last_time_);
  last_time_ = now;
  if (first_image_s_ > 0 && rendered_last_frame_) busy_frame_ms_.push_back(frame_ms_);
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  if (w > 0 && h > 0 && (w != width_ || h != height_)) {
    width_ = w;
    height_ = h;
    view_changed();
  }
  if (now - last_watch_ > 0.5) {
    last_watch_ = now;
    if (watcher_.changed()) {
      std::printf("view: %s changed, reloading\n", watcher_.path().string().c_str());
      load_material(watcher_.path().string());
    }
  }
  run_script_step();
  handle_keys();
  handle_mouse();
  if (deformer_ && !on_cpu()) {
    deformer_->apply(now, scene_.mesh);
    apply_geometry();
    ++restarts_;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  // The panel's text scales with the window: 1 at 720 pixels high, within 0.55..1.6.
  ImGui::GetIO().FontGlobalScale = std::clamp(float(height_) / 720.0f, 0.55f, 1.6f);
  ImGui::NewFrame();
  const ViewRect before = view_rect();
  if (show_ui_) draw_ui();
  ImGui::Render();
  const ViewRect after = view_rect();
  if (after.x != before.x || after.width != before.width || after.height != before.height)
    view_changed();  // the panel was resized, folded or opened

  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (width_ > 0 && height_ > 0) {
    if (on_cpu()) {
      draw_reference();
    } else {
      draw_technique();
    }
  }
  ++frames_drawn_;
  // Screenshots read the back buffer before the swap and before the panel is drawn: they show
  // the image alone (the panel's numbers go to stdout).
  if (!screenshot_path_.empty()) screenshot(std::exchange(screenshot_path_, {}));
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (!panel_screenshot_path_.empty()) screenshot(std::exchange(panel_screenshot_path_, {}));
  glfwSwapBuffers(window_);
}

void Viewer::run_script_step() {
  if (wait_frames_ > 0) {
    --wait_frames_;
    return;
  }
  const double now = glfwGetTime();
  if (now < sleep_until_) return;
  if (settling_) {
    const Technique* t = live(technique_);
    const bool done = on_cpu() ? reference_passes_ > 0 : t != nullptr && t->converged();
    if (!done && now < settle_deadline_) return;
    if (!done) std::fprintf(stderr, "view: settle: still not done after %g s\n", kSettleTimeout);
    settling_ = false;
  }
  if (script_pos_ >= script_.size()) return;
  const ScriptAction& a = script_[script_pos_++];
  if (a.verb == "orbit") {
    view_.drag(parse_float(a.args[0], "orbit DX"), parse_float(a.args[1], "orbit DY"));
    view_changed();
  } else if (a.verb == "light") {
    drag_light(scene_.lights[std::size_t(selected_light_)], parse_float(a.args[0], "light DX"),
               parse_float(a.args[1], "light DY"));
    ++versions_.lights;
    scene_changed();
  } else if (a.verb == "zoom") {
    view_.zoom(parse_float(a.args[0], "zoom STEPS"));
    view_changed();
  } else if (a.verb == "set") {
    set_parameter(a.args[0], a.args[1]);
  } else if (a.verb == "wait") {
    wait_frames_ = std::max(0, int(parse_float(a.args[0], "wait FRAMES")) - 1);
  } else if (a.verb == "key") {
    keys_.push_back(GLFW_KEY_A + (std::toupper(static_cast<unsigned char>(a.args[0][0])) - 'A'));
  } else if (a.verb == "sleep") {
    sleep_until_ = now + parse_float(a.args[0], "sleep SECONDS");
  } else if (a.verb == "settle") {
    settling_ = true;
    settle_deadline_ = now + kSettleTimeout;
  } else if (a.verb == "restart") {
    scene_changed();
  } else if (a.verb == "save") {
    save_material(a.args[0]);
  } else if (a.verb == "quit") {
    quit_ = true;
  } else if (a.verb == "screenshot") {
    screenshot_path_ = a.args[0];  // taken in frame(), after drawing
    screenshot_scripted_ = true;
  } else if (a.verb == "screenshot-panel") {
    panel_screenshot_path_ = a.args[0];  // with the panel on it
    screenshot_scripted_ = true;
  } else if (a.verb == "panel") {
    show_ui_ = a.args[0] == "on";
    view_changed();
  } else if (a.verb == "difference") {
    show_difference_ = a.args[0] == "on";
    if (show_difference_) set_render_scale(1);
  }
}

void Viewer::handle_keys() {
  const std::vector<int> keys = std::exchange(keys_, {});
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  for (int key : keys) {
    if (key == GLFW_KEY_ESCAPE) quit_ = true;
    if (key == GLFW_KEY_H) {
      show_ui_ = !show_ui_;
      view_changed();  // the image takes the panel's place, or gives it back
    }
    if (key == GLFW_KEY_E) auto_exposure_ = true;
    if (key == GLFW_KEY_D) {
      show_difference_ = !show_difference_;
      if (show_difference_) set_render_scale(1);  // the view's resolution for the comparison
    }
    if (key == GLFW_KEY_R) scene_changed();
    if (key == GLFW_KEY_L) fur_lobe_ = !fur_lobe_;  // fur: the seed's rotating lobe light
    if (key == GLFW_KEY_LEFT_BRACKET) scale_selected_light(1 / 1.25f);  // an area light's size
    if (key == GLFW_KEY_RIGHT_BRACKET) scale_selected_light(1.25f);
    if (key == GLFW_KEY_S) {
      screenshot_path_ = next_screenshot_path();  // taken after drawing
      screenshot_scripted_ = false;
    }
  }
}

void Viewer::handle_mouse() {
  const ImGuiIO& io = ImGui::GetIO();
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  const bool left = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const bool right = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
  if (!(left || right)) {
    dragging_ = false;
  } else if (!dragging_) {
    dragging_ = !io.WantCaptureMouse;  // a drag that starts on the panel belongs to the panel
  } else {
    const float dx = float(x - last_x_), dy = float(y - last_y_);
    if (dx != 0 || dy != 0) {
      if (left) {
        view_.drag(dx, dy);
        view_changed();
      } else {
        drag_light(scene_.lights[std::size_t(selected_light_)], 0.4f * dx, -0.4f * dy);
        ++versions_.lights;
        auto_exposure_ = true;  // taken once the image has settled again
        scene_changed();
      }
    }
  }
  last_x_ = x;
  last_y_ = y;
  if (scroll_ != 0 && !io.WantCaptureMouse) {
    view_.zoom(scroll_);
    view_changed();
  }
  scroll_ = 0;
}

void Viewer::view_changed() {
  ++scene_version_;  // the cached reference was of the old view
  // Moving the view while the maps refine (or after): the final pass at the refining resolution
  // until it settles again.
  if (technique_ == TechniqueId::kMaps) render_scale_ = show_difference_ ? 1.0f : refine_scale_;
  apply_camera();
  if (on_cpu()) scene_changed();
}

void Viewer::scene_changed() {
  ++restarts_;
  ++scene_version_;
  redraw_ = true;
  for (LiveTechnique& t : live_)
    if (t.technique) t.technique->restart();
  // The maps climb their levels again from the coarse one (set up before: no compiling); every
  // level parked restarts too (R, or a change none of them can see).
  for (LiveTechnique& parked : parked_maps_)
    if (parked.technique) parked.technique->restart();
  if (frame_budget_ms_ > 0 && level_ > 0 && live(TechniqueId::kMaps) != nullptr) {
    switch_maps_level(0);
    live(TechniqueId::kMaps)->restart();
  }
  if (on_cpu()) {
    // Half the view's resolution in each direction: four times fewer pixels to integrate.
    Scene small = scene_;
    const ViewRect r = view_rect();
    small.camera = view_.camera(scene_.mesh, std::max(1, r.width / 2), std::max(1, r.height / 2));
    cpu_worker_->start(small, technique_, settings_.model, technique_options());
    reference_passes_ = 0;
  } else if (cpu_worker_) {
    cpu_worker_->pause();
  }
}

void Viewer::rebuild_maps(bool settings_changed) {
  try {
    // New settings: the levels set up before are of the old ones. Back to the coarse level.
    if (settings_changed) {
      parked_maps_.clear();
      if (frame_budget_ms_ > 0) level_ = 0;
    }
    LiveTechnique& slot = live_[std::size_t(TechniqueId::kMaps)];
    std::unique_ptr<Technique> maps = make_technique(TechniqueId::kMaps);
    maps->setup(scene_, technique_options());
    slot = {std::move(maps), versions_, scene_.camera.width, scene_.camera.height};
    ++restarts_;
    apply_split();
    redraw_ = true;
  } catch (const Error& e) {
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
    pending_ = settings_;  // keep showing what runs
    if (!live(TechniqueId::kMaps)) throw;
  }
}

// The script's `set NAME VALUE`: NAME is the CLI's flag without its dashes (maps-samples,
// maps-disc-selection, object-size-mm, ...); the panel's short names (N, M, q, K, Ws, Wl, T, disc,
// size) are kept as aliases.
void Viewer::set_parameter(const std::string& given, const std::string& value) {
  static const std::vector<std::pair<std::string, std::string>> kShort = {
      {"N", "maps-samples"},    {"M", "maps-disc-points"},       {"q", "maps-q"},
      {"K", "maps-directions"}, {"Ws", "maps-radiance-map"},     {"Wl", "maps-light-map"},
      {"T", "maps-frames"},     {"disc", "maps-disc-selection"}, {"size", "object-size-mm"}};
  std::string name = given;
  for (const auto& [alias, cli] : kShort)
    if (given == alias) name = cli;
  if (name == "technique") return set_technique(value);
  if (name == "maps-disc-selection") {
    settings_.disc_selection = pending_.disc_selection = parse_disc_selection(value);
    return rebuild_maps();  // the reference does not use the disc
  }
  if (name == "model") {
    settings_.model = materials::parse_diffusion_model(value, "--script set model", true);
    pending_ = settings_;
    model_from_material_ = false;
    rebuild_maps();
    return scene_changed();  // the reference uses the model too
  }
  const float v = parse_float(value, "set " + given);
  if (name == "exposure") {
    settings_.exposure = pending_.exposure = v;
  } else if (name == "light_scale") {
    scale_selected_light(v);
  } else if (name == "object-size-mm") {
    set_object_size(v);
  } else if (name == "deform") {
    set_deform(v);
  } else {
    RenderSettings next = settings_;
    if (name == "maps-samples")
      next.samples = int(v);
    else if (name == "maps-disc-points")
      next.disc_points = int(v);
    else if (name == "maps-q")
      next.q = v;
    else if (name == "maps-directions")
      next.directions = int(v);
    else if (name == "maps-radiance-map")
      next.radiance_map_size = int(v);
    else if (name == "maps-light-map")
      next.light_map_size = int(v);
    else if (name == "maps-frames")
      next.frames = int(v);
    else
      throw Error("--script: set " + given +
                  ": expected maps-samples, maps-disc-points, maps-q, maps-directions, "
                  "maps-radiance-map, maps-light-map, maps-frames, maps-disc-selection, technique, "
                  "model, exposure, object-size-mm, deform or light_scale (or the panel's N, M, q, "
                  "K, Ws, Wl, T, disc, size)");
    next.validate();
    mark_explicit(name);
    settings_ = pending_ = next;
    rebuild_maps();
  }
}

void Viewer::load_material(const std::string& source) {
  try {
    scene_.material = materials::load_material(source);
  } catch (const Error& e) {
    message_ = e.what();  // keep the material that works
    std::fprintf(stderr, "view: %s\n", e.what());
    return;
  }
  material_source_ = source;
  watcher_ = std::filesystem::is_regular_file(source) ? FileWatcher(source) : FileWatcher();
  message_ = "material: " + scene_.material.name;
  auto_exposure_ = true;  // another material: another brightness
  if (model_from_material_) {
    const DiffusionModel model = materials::preferred_model(scene_.material);
    if (model != settings_.model) {
      settings_.model = pending_.model = model;
      rebuild_maps();  // the model is compiled into the maps' programs
    }
  }
  glfwSetWindowTitle(window_,
                     ("lucent view - " + scene_.material.name + " on " + scene_.mesh.name).c_str());
  ++versions_.material;
  scene_changed();
}

void Viewer::set_object_size(double mm) {
  if (!(mm > 0) || !std::isfinite(mm)) {
    message_ = "object size: must be positive (mm)";
    return;
  }
  // The lighting geometry scales with the object (point lights move out with it and keep the
  // irradiance they give it): only the material's length scale against the object changes.
  const float s = float(mm / object_size_mm_);
  object_size_mm_ = mm;
  for (Vec3f& p : rest_mesh_.positions) p *= s;
  for (Light& light : scene_.lights) {
    if (light.type == LightType::kPoint) {
      light.position *= s;
      light.radiance *= s * s;
    }
    // An area light scaled about the centre keeps the solid angle it subtends: same radiance.
    for (Vec3f& p : light.polygon) p *= s;
    if (light.type == LightType::kArea) light.position = area_light_centroid(light);
  }
  if (deformer_) deformer_.emplace(rest_mesh_, deform_amplitude_);
  scene_.mesh = rest_mesh_;
  apply_geometry();
  ++versions_.lights;
  view_changed();
  scene_changed();
}

void Viewer::scale_selected_light(float scale) {
  Light& light = scene_.lights[std::size_t(selected_light_)];
  if (!resize_light(light, scale)) {
    message_ = "light size: only an area light (rect) can be resized, by a scale > 0";
    return;
  }
  ++versions_.lights;
  scene_changed();
}

void Viewer::set_deform(float amplitude) {
  deform_amplitude_ = std::clamp(amplitude, 0.0f, 0.2f);
  if (deform_amplitude_ > 0) {
    deformer_.emplace(rest_mesh_, deform_amplitude_);
  } else if (deformer_) {
    deformer_.reset();
    scene_.mesh = rest_mesh_;
    apply_geometry();
    scene_changed();
  }
  apply_split();  // whole frames while the mesh moves
}

void Viewer::apply_geometry() {
  ++versions_.geometry;  // every technique takes it at its next frame
}

std::filesystem::path Viewer::next_screenshot_path() const {
  for (int i = 1;; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "lucent_view_%03d.png", i);
    if (!std::filesystem::exists(name)) return name;
  }
}

void Viewer::screenshot(const std::filesystem::path& path) {
  std::vector<std::uint8_t> rgb(std::size_t(width_) * height_ * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  imaging::RawImage image(width_, height_, 255);
  for (int y = 0; y < height_; ++y) {
    const std::size_t row = std::size_t(height_ - 1 - y) * std::size_t(width_) * 3;
    for (int x = 0; x < width_; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = rgb[row + std::size_t(x) * 3 + c];
    }
  }
  try {
    imaging::write_png(path, image);
    commit_pending_outputs();  // a screenshot appears when taken, not when the viewer closes
    ++screenshots_;
    message_ = "wrote " + path.string();
    std::printf("view: wrote %s (%dx%d, frame %d of %d)\n", path.string().c_str(), width_, height_,
                maps_frames(), settings_.frames);
    std::fflush(stdout);
  } catch (const Error& e) {
    // A script asked for it: the run fails with it (a failed screenshot exited 0); a key press
    // only says so on the panel and stderr.
    if (std::exchange(screenshot_scripted_, false)) throw;
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
  }
}

}  // namespace viewer_detail

int run_viewer(const ViewerOptions& options) {
  viewer_detail::Viewer viewer(options);
  return viewer.run();
}

}  // namespace lucent::render
