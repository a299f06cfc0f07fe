// `lucent view` (see viewer.h): one GLFW window with an OpenGL 4.5 core context, the radiance-map
// renderer drawing into it, Dear ImGui's panel on top, and the CPU reference on a worker thread.
#include "lucent/render/viewer.h"

// clang-format off
#include "gl_api.h"  // first: GLFW must not pull in the legacy GL header
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
// clang-format on
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "lucent/acquire/image_io.h"
#include "lucent/materials/error.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/tone_map.h"

namespace lucent::render {
namespace {

// ---------------------------------------------------------------------------------------------
// The script: one action per frame.

struct ScriptAction {
  std::string verb;
  std::vector<std::string> args;
};

std::vector<ScriptAction> parse_script(const std::string& text) {
  std::vector<ScriptAction> actions;
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    std::stringstream words(item);
    ScriptAction action;
    if (!(words >> action.verb)) continue;
    for (std::string w; words >> w;) action.args.push_back(w);
    const std::string& v = action.verb;
    const std::size_t n = action.args.size();
    const bool ok = ((v == "orbit" || v == "light" || v == "set") && n == 2) ||
                    ((v == "zoom" || v == "wait" || v == "sleep" || v == "screenshot") &&
                     n == 1) ||
                    (v == "key" && n == 1 && action.args[0].size() == 1 &&
                     std::isalpha(static_cast<unsigned char>(action.args[0][0]))) ||
                    ((v == "restart" || v == "settle" || v == "quit") && n == 0);
    if (!ok) {
      const auto first = item.find_first_not_of(' ');
      const auto last = item.find_last_not_of(' ');
      throw Error("--script: '" + item.substr(first, last - first + 1) +
                  "': expected orbit DX DY, light DX DY, zoom STEPS, set NAME VALUE, key LETTER, "
                  "wait FRAMES, sleep SECONDS, settle, screenshot FILE.png, restart or quit");
    }
    actions.push_back(std::move(action));
  }
  return actions;
}

float parse_float(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const float v = std::strtof(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw Error("--script: " + what + ": expected a number, got '" + text + "'");
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// The CPU reference on a worker thread: one pass after another (new samples each), summed until the
// scene changes; the main thread shows the running mean.

class ReferenceWorker {
 public:
  ReferenceWorker() : thread_([this] { loop(); }) {}
  ~ReferenceWorker() {
    {
      std::lock_guard lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

  /// Starts over on `scene` (what the worker is doing now is thrown away when it finishes).
  void start(const Scene& scene, DiffusionModel model, const ReferenceOptions& options) {
    {
      std::lock_guard lock(mutex_);
      job_ = Job{scene, model, options, ++generation_};
      sum_ = ImageRgb();
      passes_ = 0;
      error_.clear();
      fresh_ = false;
    }
    wake_.notify_all();
  }
  /// Stops after the current pass.
  void pause() {
    std::lock_guard lock(mutex_);
    job_.reset();
    ++generation_;
  }
  /// The mean over the passes so far, when a pass has finished since the last call.
  bool take(ImageRgb& mean, int& passes, std::string& error) {
    std::lock_guard lock(mutex_);
    error = error_;
    if (!fresh_) return false;
    fresh_ = false;
    mean = sum_;
    for (float& v : mean.data) v /= float(passes_);
    passes = passes_;
    return true;
  }

 private:
  struct Job {
    Scene scene;
    DiffusionModel model;
    ReferenceOptions options;
    std::uint64_t generation;
  };

  void loop() {
    for (;;) {
      Job job;
      int pass = 0;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return quit_ || job_.has_value(); });
        if (quit_) return;
        job = *job_;
        pass = passes_;
      }
      ReferenceOptions options = job.options;
      options.passes = 1;
      options.seed = job.options.seed + std::uint64_t(pass) * 7919;
      options.progress = nullptr;
      std::optional<ImageRgb> image;
      std::string error;
      try {
        image = render_reference(job.scene, job.model, options).image;
      } catch (const std::exception& e) {
        error = e.what();
      }
      std::lock_guard lock(mutex_);
      if (job.generation != generation_) continue;  // the scene changed meanwhile
      if (!image) {
        error_ = error;
        job_.reset();
        continue;
      }
      if (sum_.data.empty()) sum_ = ImageRgb(image->width, image->height);
      for (std::size_t i = 0; i < sum_.data.size(); ++i) sum_.data[i] += image->data[i];
      ++passes_;
      fresh_ = true;
      if (passes_ >= kMaxPasses) job_.reset();
    }
  }

  static constexpr int kMaxPasses = 1000;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> job_;
  std::uint64_t generation_ = 0;
  ImageRgb sum_;
  int passes_ = 0;
  bool fresh_ = false;
  bool quit_ = false;
  std::string error_;
  std::thread thread_;  // last: starts after the members it uses exist
};

// ---------------------------------------------------------------------------------------------

struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback([](int, const char* what) { last_error() = what; });
    if (!glfwInit()) {
      throw Error(
          "view: no window system (" + last_error() +
          "); lucent view needs an X display: run it under `xvfb-run -a` for a virtual one");
    }
  }
  ~GlfwSession() { glfwTerminate(); }
  static std::string& last_error() {
    static std::string text;
    return text;
  }
};

constexpr std::array<int, 6> kMapSizes = {64, 128, 256, 512, 1024, 2048};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  int run();

 private:
  void frame();
  void handle_mouse();
  void handle_keys();
  void run_script_step();
  void draw_ui();
  void draw_reference();

  void view_changed();
  void scene_changed();  // lights, material or geometry: restart whatever is accumulating
  void rebuild_maps();   // new RenderSettings: new textures and programs
  void set_parameter(const std::string& name, const std::string& value);
  void load_material(const std::string& source);
  void set_object_size(double mm);
  void set_deform(float amplitude);
  void set_technique(const std::string& technique);
  void screenshot(const std::filesystem::path& path);
  std::filesystem::path next_screenshot_path() const;

  ViewerOptions options_;
  GlfwSession glfw_;
  GLFWwindow* window_ = nullptr;
  int width_ = 0, height_ = 0;  // framebuffer pixels

  Scene scene_;
  Mesh rest_mesh_;  // undeformed, at the current object size
  std::optional<SineDeformer> deformer_;
  float deform_amplitude_ = 0;
  double object_size_mm_ = 100;
  RenderSettings settings_, pending_;
  bool model_from_material_ = true;
  OrbitView view_;
  std::string technique_;
  std::unique_ptr<RadianceMapRenderer> maps_;
  std::unique_ptr<ReferenceWorker> reference_;
  FileWatcher watcher_;
  double last_watch_ = 0;
  std::string material_source_;
  std::array<char, 512> material_path_{};
  int selected_light_ = 0;

  // The reference image on screen.
  GLuint reference_texture_ = 0, reference_fbo_ = 0;
  int reference_w_ = 0, reference_h_ = 0, reference_passes_ = 0;
  std::string reference_error_;

  std::vector<ScriptAction> script_;
  std::size_t script_pos_ = 0;
  double sleep_until_ = 0, settle_deadline_ = 0;
  bool settling_ = false;
  static constexpr double kSettleTimeout = 300;  // s
  std::filesystem::path screenshot_path_;
  int wait_frames_ = 0;
  bool quit_ = false;
  bool show_ui_ = true;
  std::string message_;  // last error or notice, shown in the panel
  std::vector<int> keys_;
  float scroll_ = 0;
  bool dragging_ = false;
  double last_x_ = 0, last_y_ = 0;
  long frames_drawn_ = 0;
  int restarts_ = 0, screenshots_ = 0;
  double frame_ms_ = 0, last_time_ = 0;
};

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
  settings_.validate();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  window_ = glfwCreateWindow(options.scene.camera.width, options.scene.camera.height,
                             ("lucent view - " + scene_.material.name + " on " + scene_.mesh.name)
                                 .c_str(),
                             nullptr, nullptr);
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
    if (action == GLFW_PRESS) static_cast<Viewer*>(glfwGetWindowUserPointer(w))->keys_.push_back(key);
  });
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
  ImGui::GetIO().FontGlobalScale = 0.9f;
  ImGui::StyleColorsDark();
  ImGui::GetStyle().ScaleAllSizes(0.8f);
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 450 core");

  glfwGetFramebufferSize(window_, &width_, &height_);
  scene_.camera = view_.camera(scene_.mesh, std::max(width_, 1), std::max(height_, 1));
  if (std::filesystem::is_regular_file(material_source_)) watcher_ = FileWatcher(material_source_);
  std::snprintf(material_path_.data(), material_path_.size(), "%s", material_source_.c_str());
  if (deform_amplitude_ != options.deform_amplitude) set_deform(options.deform_amplitude);
  rebuild_maps();
  reference_ = std::make_unique<ReferenceWorker>();
  if (technique_ == "reference") scene_changed();
  last_time_ = glfwGetTime();
}

Viewer::~Viewer() {
  reference_.reset();
  if (reference_fbo_ != 0) glDeleteFramebuffers(1, &reference_fbo_);
  if (reference_texture_ != 0) glDeleteTextures(1, &reference_texture_);
  maps_.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window_);
}

int Viewer::run() {
  while (!quit_ && !glfwWindowShouldClose(window_)) {
    // Frames as fast as they come while the maps accumulate or the mesh moves; otherwise wake for
    // input, a finished reference pass (the worker needs the CPU more than the window does) and,
    // now and then, to watch the material file.
    const bool accumulating =
        technique_ == "maps" && maps_ && (deformer_ || !maps_->converged());
    if (accumulating) {
      glfwPollEvents();
    } else {
      glfwWaitEventsTimeout(script_pos_ < script_.size() || technique_ == "reference" ? 0.05 : 0.25);
    }
    frame();
  }
  std::printf(
      "view: %ld frames drawn, %d restarts, %d screenshots; technique %s, accumulated %d of %d "
      "frames\n",
      frames_drawn_, restarts_, screenshots_, technique_.c_str(), maps_ ? maps_->accumulated_frames() : 0,
      settings_.frames);
  return 0;
}

void Viewer::frame() {
  const double now = glfwGetTime();
  frame_ms_ = 1000 * (now - last_time_);
  last_time_ = now;
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
  if (deformer_ && technique_ == "maps" && maps_) {
    deformer_->apply(now, scene_.mesh);
    maps_->set_geometry(scene_.mesh.positions, scene_.mesh.normals);
    ++restarts_;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  if (show_ui_) draw_ui();
  ImGui::Render();

  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (width_ > 0 && height_ > 0) {
    if (technique_ == "maps" && maps_) {
      maps_->render_frame();
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      maps_->present(settings_.exposure, width_, height_);
    } else {
      draw_reference();
    }
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  ++frames_drawn_;
  // Screenshots read the back buffer before the swap.
  if (!screenshot_path_.empty()) screenshot(std::exchange(screenshot_path_, {}));
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
    const bool done = technique_ == "maps" ? (maps_ && maps_->converged()) : reference_passes_ > 0;
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
    if (maps_) maps_->set_lights(scene_.lights);
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
  } else if (a.verb == "quit") {
    quit_ = true;
  } else if (a.verb == "screenshot") {
    screenshot_path_ = a.args[0];  // taken in frame(), after drawing
  }
}

void Viewer::handle_keys() {
  const std::vector<int> keys = std::exchange(keys_, {});
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  for (int key : keys) {
    if (key == GLFW_KEY_ESCAPE) quit_ = true;
    if (key == GLFW_KEY_H) show_ui_ = !show_ui_;
    if (key == GLFW_KEY_R) scene_changed();
    if (key == GLFW_KEY_S) screenshot_path_ = next_screenshot_path();  // taken after drawing
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
        if (maps_) maps_->set_lights(scene_.lights);
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
  scene_.camera = view_.camera(scene_.mesh, std::max(width_, 1), std::max(height_, 1));
  if (maps_) maps_->set_camera(scene_.camera);  // the maps do not depend on the view
  if (technique_ == "reference") scene_changed();
}

void Viewer::scene_changed() {
  ++restarts_;
  if (maps_) maps_->restart();
  if (technique_ == "reference") {
    // Half the window's resolution in each direction: four times fewer pixels to integrate.
    Scene small = scene_;
    small.camera.width = std::max(1, width_ / 2);
    small.camera.height = std::max(1, height_ / 2);
    reference_->start(small, settings_.model, options_.reference);
    reference_passes_ = 0;
  } else if (reference_) {
    reference_->pause();
  }
}

void Viewer::rebuild_maps() {
  try {
    auto maps = std::make_unique<RadianceMapRenderer>();
    RadianceMapOptions map_options;
    map_options.time_stages = true;
    maps->setup(scene_, settings_, map_options);
    maps_ = std::move(maps);
    ++restarts_;
  } catch (const Error& e) {
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
    pending_ = settings_;  // keep showing what runs
    if (!maps_) throw;
  }
}

void Viewer::set_parameter(const std::string& name, const std::string& value) {
  if (name == "technique") return set_technique(value);
  if (name == "disc") {
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
  const float v = parse_float(value, "set " + name);
  if (name == "exposure") {
    settings_.exposure = pending_.exposure = v;
  } else if (name == "size") {
    set_object_size(v);
  } else if (name == "deform") {
    set_deform(v);
  } else {
    RenderSettings next = settings_;
    if (name == "N") next.samples = int(v);
    else if (name == "M") next.disc_points = int(v);
    else if (name == "q") next.q = v;
    else if (name == "K") next.directions = int(v);
    else if (name == "Ws") next.radiance_map_size = int(v);
    else if (name == "Wl") next.light_map_size = int(v);
    else if (name == "T") next.frames = int(v);
    else
      throw Error("--script: set " + name +
                  ": expected N, M, q, K, Ws, Wl, T, exposure, size, deform, disc, technique or model");
    next.validate();
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
  if (model_from_material_ && !scene_.material.model.empty()) {
    settings_.model = pending_.model =
        materials::parse_diffusion_model(scene_.material.diffusion_model(), "material model", true);
  }
  glfwSetWindowTitle(window_,
                     ("lucent view - " + scene_.material.name + " on " + scene_.mesh.name).c_str());
  if (maps_) maps_->set_material(scene_.material);
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
  }
  if (deformer_) deformer_.emplace(rest_mesh_, deform_amplitude_);
  scene_.mesh = rest_mesh_;
  if (maps_) {
    maps_->set_geometry(scene_.mesh.positions, scene_.mesh.normals);
    maps_->set_lights(scene_.lights);
  }
  view_changed();
  scene_changed();
}

void Viewer::set_deform(float amplitude) {
  deform_amplitude_ = std::clamp(amplitude, 0.0f, 0.2f);
  if (deform_amplitude_ > 0) {
    deformer_.emplace(rest_mesh_, deform_amplitude_);
  } else if (deformer_) {
    deformer_.reset();
    scene_.mesh = rest_mesh_;
    if (maps_) maps_->set_geometry(scene_.mesh.positions, scene_.mesh.normals);
    scene_changed();
  }
}

void Viewer::set_technique(const std::string& technique) {
  if (technique != "maps" && technique != "reference") {
    throw Error("technique: expected maps or reference, got '" + technique + "'");
  }
  technique_ = technique;
  scene_changed();
}

void Viewer::draw_reference() {
  ImageRgb mean;
  int passes = 0;
  if (reference_->take(mean, passes, reference_error_)) {
    // Tone-mapped on the CPU with the same curve as the maps' present(), then blitted.
    ToneMapOptions tone;
    tone.exposure = settings_.exposure;
    const acquire::RawImage srgb = tone_map(mean, tone);
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
    reference_passes_ = passes;
  }
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (reference_fbo_ != 0 && reference_passes_ > 0) {
    // Row 0 of the image is the top: flip while blitting.
    glBlitNamedFramebuffer(reference_fbo_, 0, 0, 0, reference_w_, reference_h_, 0, height_,
                           width_, 0, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }
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
  acquire::RawImage image(width_, height_, 255);
  for (int y = 0; y < height_; ++y) {
    const std::size_t row = std::size_t(height_ - 1 - y) * std::size_t(width_) * 3;
    for (int x = 0; x < width_; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = rgb[row + std::size_t(x) * 3 + c];
    }
  }
  try {
    acquire::write_png(path, image);
    ++screenshots_;
    message_ = "wrote " + path.string();
    std::printf("view: wrote %s (%dx%d, frame %d of %d)\n", path.string().c_str(), width_, height_,
                maps_ ? maps_->accumulated_frames() : 0, settings_.frames);
    std::fflush(stdout);
  } catch (const Error& e) {
    message_ = e.what();
    std::fprintf(stderr, "view: %s\n", e.what());
  }
}

bool slider_done() { return ImGui::IsItemDeactivatedAfterEdit(); }

void section(const char* title) {
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

void Viewer::draw_ui() {
  ImGui::SetNextWindowPos(ImVec2(6, 6), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("lucent", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::PushItemWidth(130);

  // Material: the library, or a file (reloaded when it changes on disk).
  if (ImGui::BeginCombo("material", scene_.material.name.c_str())) {
    for (const std::string& name : materials::library_material_names()) {
      if (ImGui::Selectable(name.c_str(), name == material_source_)) load_material(name);
    }
    ImGui::EndCombo();
  }
  ImGui::InputText("file", material_path_.data(), material_path_.size());
  ImGui::SameLine();
  if (ImGui::Button("load")) load_material(material_path_.data());

  // Technique and model.
  int technique = technique_ == "maps" ? 0 : 1;
  if (ImGui::RadioButton("radiance maps", &technique, 0)) set_technique("maps");
  ImGui::SameLine();
  if (ImGui::RadioButton("CPU reference", &technique, 1)) set_technique("reference");
  int model = settings_.model == DiffusionModel::kDirectionalDipole ? 0 : 1;
  if (ImGui::RadioButton("directional dipole", &model, 0) ||
      ImGui::RadioButton("standard dipole", &model, 1)) {
    settings_.model = pending_.model =
        model == 0 ? DiffusionModel::kDirectionalDipole : DiffusionModel::kDipole;
    model_from_material_ = false;
    rebuild_maps();
    scene_changed();
  }

  // The speed/accuracy knobs: applied when a slider is let go (they rebuild the maps).
  section("radiance maps");
  bool apply = false;
  int disc = pending_.disc_selection == DiscSelection::kStrata ? 0 : 1;
  if (ImGui::RadioButton("strata", &disc, 0) || ImGui::RadioButton("N nearest (seed)", &disc, 1)) {
    pending_.disc_selection = disc == 0 ? DiscSelection::kStrata : DiscSelection::kNearest;
    apply = true;
  }
  ImGui::SliderInt("N samples", &pending_.samples, 1, std::min(pending_.disc_points, 512));
  apply |= slider_done();
  ImGui::SliderInt("M disc points", &pending_.disc_points, 1, 4000);
  apply |= slider_done();
  float q = float(pending_.q);
  if (ImGui::SliderFloat("q", &q, 0.1f, 10.0f, "%.2f", ImGuiSliderFlags_Logarithmic)) pending_.q = q;
  apply |= slider_done();
  ImGui::SliderInt("K directions", &pending_.directions, 1, 64);
  apply |= slider_done();
  ImGui::SliderInt("T frames", &pending_.frames, 1, 1000);
  apply |= slider_done();
  for (auto [label, value] : {std::pair{"W_s radiance map", &pending_.radiance_map_size},
                              std::pair{"W_l light map", &pending_.light_map_size}}) {
    int index = int(std::find(kMapSizes.begin(), kMapSizes.end(), *value) - kMapSizes.begin());
    index = std::min(index, int(kMapSizes.size()) - 1);
    if (ImGui::SliderInt(label, &index, 0, int(kMapSizes.size()) - 1,
                         std::to_string(kMapSizes[std::size_t(index)]).c_str())) {
      *value = kMapSizes[std::size_t(index)];
    }
    apply |= slider_done();
  }
  if (apply) {
    pending_.samples = std::min(pending_.samples, pending_.disc_points);
    try {
      pending_.validate();
      settings_ = pending_;
      rebuild_maps();
    } catch (const Error& e) {
      message_ = e.what();
      pending_ = settings_;
    }
  }

  section("scene");
  ImGui::SliderFloat("exposure", &settings_.exposure, 0.01f, 100.0f, "%.3g",
                     ImGuiSliderFlags_Logarithmic);
  pending_.exposure = settings_.exposure;
  float size = float(object_size_mm_);
  ImGui::SliderFloat("object size mm", &size, 1.0f, 2000.0f, "%.4g", ImGuiSliderFlags_Logarithmic);
  if (slider_done()) set_object_size(size);
  float deform = deform_amplitude_;
  ImGui::SliderFloat("deform", &deform, 0.0f, 0.2f, "%.3f");
  if (slider_done()) set_deform(deform);
  if (scene_.lights.size() > 1) {
    ImGui::SliderInt("dragged light", &selected_light_, 0, int(scene_.lights.size()) - 1);
  }
  if (technique_ == "reference" && deformer_) ImGui::TextUnformatted("(the deformer pauses for the reference)");

  section("progress");
  if (technique_ == "maps" && maps_) {
    const RadianceMapStats& s = maps_->stats();
    ImGui::Text("frames %d / %d%s", maps_->accumulated_frames(), settings_.frames,
                maps_->converged() ? "  (converged)" : "");
    const StageTimes& t = s.last_wall;
    ImGui::Text("light map   %8.2f ms", t.light_map_ms);
    ImGui::Text("radiance map%8.2f ms", t.radiance_map_ms);
    ImGui::Text("mip blur    %8.2f ms", t.mip_blur_ms);
    ImGui::Text("final       %8.2f ms", t.final_ms);
    ImGui::Text("window frame %7.1f ms", frame_ms_);
    ImGui::Text("disc: sigma* %.3g /mm, rho %.3g of R %.3g mm", s.sigma_star_per_mm,
                s.used_disc_radius_mm, s.disc_radius_mm);
    if (s.uncovered_fraction > 0) {
      ImGui::Text("unseen by every layer: %.1f%% of pixels", 100 * s.uncovered_fraction);
    }
  } else {
    ImGui::Text("reference passes %d (%d samples each)", reference_passes_,
                options_.reference.surface_samples);
    if (!reference_error_.empty()) ImGui::TextWrapped("%s", reference_error_.c_str());
  }
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
  ImGui::TextDisabled("drag: orbit  right drag: light  wheel: zoom");
  ImGui::TextDisabled("S screenshot  R restart  H hide  Esc quit");
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace

int run_viewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace lucent::render
