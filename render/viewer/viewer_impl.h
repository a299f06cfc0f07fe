// The viewer's internals (render/viewer/viewer.cpp, viewer_panel.cpp): the script, the reference
// worker thread, the GLFW session and the Viewer class. Private to lucent_viewer.
#pragma once

// clang-format off
#include "gl_api.h"  // first: GLFW must not pull in the legacy GL header
#define GLFW_INCLUDE_NONE
#include <functional>
#include <GLFW/glfw3.h>
// clang-format on
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/sh_renderer.h"
#include "lucent/render/tone_map.h"

#include "lucent/render/image_compare.h"
#include "lucent/render/technique.h"
#include "lucent/render/viewer.h"
#include "viewer_script.h"

namespace lucent::render::viewer_detail {

// ---------------------------------------------------------------------------------------------
// A CPU technique (the reference, the path tracer) on a worker thread: one pass after another (new
// samples each), summed until the scene changes; the main thread shows the running mean.

class CpuWorker {
 public:
  CpuWorker() : thread_([this] { loop(); }) {}
  ~CpuWorker() {
    {
      std::lock_guard lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

  /// Starts over on `scene` (what the worker is doing now is thrown away when it finishes).
  void start(const Scene& scene, TechniqueId id, DiffusionModel model,
             const TechniqueOptions& options) {
    {
      std::lock_guard lock(mutex_);
      job_ = Job{scene, id, model, options, ++generation_};
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
    TechniqueId id;
    DiffusionModel model;
    TechniqueOptions options;
    std::uint64_t generation;
  };

  // One pass of the job's technique with its own seed.
  static ImageRgb render_pass(const Job& job, int pass) {
    const std::uint64_t seed = job.options.reference.seed + std::uint64_t(pass) * 7919;
    if (job.id == TechniqueId::kPathtrace) {
      PathTraceOptions options = job.options.pathtrace;
      options.passes = 1;
      options.seed = seed;
      options.progress = nullptr;
      return render_pathtrace(job.scene, options).image;
    }
    ReferenceOptions options = job.options.reference;
    options.passes = 1;
    options.seed = seed;
    options.progress = nullptr;
    return render_reference(job.scene, job.model, options).image;
  }

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
      std::optional<ImageRgb> image;
      std::string error;
      try {
        image = render_pass(job, pass);
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

// How many times each part of the scene has changed: a technique takes the parts whose count moved
// since it last drew (Viewer::sync), so that one left aside catches up when it is chosen again.
struct SceneVersions {
  std::uint64_t camera = 0, lights = 0, material = 0, geometry = 0;
};

// A frame-by-frame technique the viewer has made (the maps at start, the others when first chosen)
// and the scene it has.
struct LiveTechnique {
  std::unique_ptr<Technique> technique;
  SceneVersions seen;
  int width = 0, height = 0;  // the camera's size at setup
};

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
  void draw_ui();              // the panel: the four below in order
  void draw_choices();         // material, technique, model, material controls
  void draw_maps_knobs();      // the radiance maps' speed/accuracy knobs
  void draw_scene_controls();  // exposure, object size, deformer, lights
  void draw_progress();        // statistics, the difference view
  void draw_reference();
  /// The current technique renders on the CPU, pass after pass on the worker (reference,
  /// pathtrace).
  bool on_cpu() const { return !technique_info(technique_).gpu; }
  // One frame of the current frame-by-frame technique (made and brought up to date first), on
  // screen or in the difference view; one that fails says why and hands over to the maps.
  void draw_technique();
  Technique& current_technique();  // made, set up for the window's size, synced
  void sync(LiveTechnique& live);  // the scene's parts that changed since it last drew
  TechniqueOptions technique_options() const;
  Technique* live(TechniqueId id) const { return live_[std::size_t(id)].technique.get(); }
  int maps_frames() const;  // the maps' accumulated frames (0 before they exist)
  void apply_geometry();    // scene_.mesh changed: every technique takes it at its next frame

  void view_changed();
  void scene_changed();  // lights, material or geometry: restart whatever is accumulating
  // New RenderSettings (settings_changed: the levels parked before are dropped) or a level not set
  // up yet: new textures and programs.
  void rebuild_maps(bool settings_changed = true);
  // The maps at another level of the ladder: the current one parked (programs compiled, textures
  // kept), the other one taken from the park or set up.
  void switch_maps_level(int level);
  void level_prepared(const RadianceMapRenderer& maps);
  void fit_to_budget();
  void apply_split();  // the frame split for the current level (plan_split)
  void set_parameter(const std::string& name, const std::string& value);
  void load_material(const std::string& source);
  void set_object_size(double mm);
  void scale_selected_light(float scale);  ///< area lights: `[` / `]`, set light_scale S
  void set_deform(float amplitude);
  void set_technique(const std::string& name);  // a registry name (the script's `set technique`)
  void set_technique(TechniqueId technique);
  void screenshot(const std::filesystem::path& path);
  void blit(const ImageRgb& image, float exposure);  // tone-mapped, stretched to the window
  void draw_difference();  // the current technique against the cached reference
  ImageRgb technique_image();  // the image shown: the current technique's (or the level below's)
  void draw_material_controls();     // colour and mean free path, or the coefficients
  void draw_coefficient_controls(materials::Material& m, bool& changed);
  void apply_material(const materials::Material& material);
  void save_material(const std::string& path);  // the edited material, as a material file
  // The frame budget (frame_budget.h): the maps' settings at the current level of the ladder made
  // from the requested settings_, and after each measured frame the level and the resolution.
  RenderSettings running_settings() const;
  void budget_after_frame(Technique& t);
  Technique* previous_maps();  // the level below, converged: shown until the current has a frame
  void set_render_scale(float scale);
  void apply_camera();  // the camera of the view rect at the render scale (the maps only)
  // The part of the window the image is drawn in (GL's lower-left origin): beside the panel.
  struct ViewRect {
    int x = 0, y = 0, width = 1, height = 1;
  };
  ViewRect view_rect() const;
  float default_panel_width() const;
  void mark_explicit(const std::string& knob);  // a knob set by hand is kept at every level
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
  TechniqueId technique_ = TechniqueId::kMaps;
  // By TechniqueId; the CPU techniques' slots stay empty (they run on cpu_worker_, a thread).
  std::array<LiveTechnique, 6> live_;
  SceneVersions versions_;
  bool fur_lobe_ = false;  // the seed's rotating lobe light instead of the scene's lights
  std::unique_ptr<CpuWorker> cpu_worker_;  // the reference or the path tracer
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
  std::filesystem::path screenshot_path_, panel_screenshot_path_;
  bool screenshot_scripted_ = false;  // a script's screenshot that fails ends the run with its error
  int wait_frames_ = 0;
  bool quit_ = false;
  bool show_ui_ = true;
  bool auto_exposure_ = false;
  // The reference's latest mean, valid for the scene and view of scene_version_ == its version:
  // what the difference view compares the maps against.
  ImageRgb cached_reference_;
  std::string cached_label_ = "reference";  // the technique that made it (reference, pathtrace)
  std::uint64_t scene_version_ = 0, reference_version_ = ~std::uint64_t(0);
  bool show_difference_ = false;
  std::string difference_text_;
  long difference_frame_ = -1000;  // frame of the last printed difference
  std::string message_;            // last error or notice, shown in the panel
  std::vector<int> keys_;
  float scroll_ = 0;
  bool dragging_ = false;
  double last_x_ = 0, last_y_ = 0;
  long frames_drawn_ = 0, frames_rendered_ = 0;
  // The frame budget: the level of the maps' ladder, the cost model of the frames measured, the
  // resolution while refining (1 once converged), whether the next frame is a level's first (the
  // programs compile in it; not measured).
  double frame_budget_ms_ = 50;
  FixedKnobs fixed_;
  int level_ = 0;
  std::vector<LiveTechnique> parked_maps_;  // by level: the maps set up at the other levels
  double layer_ms_ = 0, final_ms_ = 0;      // measured at the current level (running means)
  RenderSettings measured_at_;              // the level layer_ms_ was measured at
  bool layer_ms_prior_ = false;             // layer_ms_ a level's prior (level_prepared)
  FrameSplit split_;                        // the maps' frame split now
  float render_scale_ = 1, refine_scale_ = 1;
  bool redraw_ = true;                    // something changed since the last rendered frame
  bool exposure_pending_frames_ = false;  // auto exposure waits for a few accumulated frames
  // How the window answered (the summary): when the first image was shown, s from the command's
  // start, and each frame that rendered since, ms.
  double first_image_s_ = 0;
  std::vector<double> busy_frame_ms_;
  bool rendered_last_frame_ = false;
  double start_time_ = 0;
  // The panel: docked at the left; its width as the person left it (0 when folded or hidden), and
  // the widest line it holds (a label wider than the panel would be clipped).
  float panel_width_ = 0, panel_content_width_ = 0, panel_inner_width_ = 0;
  bool panel_collapsed_ = false;
  float panel_bar_height_ = 0;      // the folded panel's title bar, px
  bool edit_coefficients_ = false;  // the material in coefficients instead of colour and mfp
  std::array<char, 512> save_path_{};
  int restarts_ = 0, screenshots_ = 0;
  double frame_ms_ = 0, last_time_ = 0;
};

}  // namespace lucent::render::viewer_detail
