// `lucent view`: the same scene options as `lucent render`, shown in a window with live controls
// (lucent::render::run_viewer). Needs an X display; `xvfb-run -a lucent view ...` gives a virtual
// one.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "progress.h"
#include "scene_options.h"
#include "shader_cache.h"
#include "technique_flags.h"
#include "validators.h"
#if LUCENT_HAS_VIEWER
#include "lucent/render/viewer.h"
#endif

namespace lucent::cli {
namespace {

struct ViewArguments {
  SceneArguments scene;
  float deform = 0;
  std::string script;
  bool hide_panel = false;
  double frame_budget_ms = 50;
  render::FixedKnobs fixed;
};

void run_view(ViewArguments& args) {
#if LUCENT_HAS_VIEWER
  const auto started = std::chrono::steady_clock::now();
  if (!(args.deform >= 0 && args.deform <= 0.2f)) {
    throw Error("--deform: expected an amplitude in [0, 0.2] (fraction of the object's size)");
  }
  use_shader_cache();
  const bool model_given = !args.scene.model.empty();
  StageProgress progress("view", false);
  progress.stage("loading the scene (mesh, material, lights)", 0.0);
  SceneSetup setup = build_scene(args.scene);
  progress.finish();
  render::ViewerOptions options;
  options.scene = std::move(setup.scene);
  options.material_source = args.scene.material;
  const render::TechniqueOptions& flags = args.scene.options;
  options.settings = flags.settings;
  options.model_follows_material = !model_given;
  options.reference = flags.reference;
  options.pathtrace = flags.pathtrace;
  options.view = {setup.azimuth_deg, setup.elevation_deg, setup.distance_radii};
  options.object_size_mm = args.scene.object_size_mm;
  options.technique = args.scene.technique_id;
  options.sh = flags.sh;
  options.hierarchical = flags.hierarchical;
  options.fur = flags.fur;
  options.deform_amplitude = args.deform;
  options.script = args.script;
  options.hide_panel = args.hide_panel;
  options.frame_budget_ms = args.frame_budget_ms;
  options.fixed = args.fixed;
  options.started = started;
  options.auto_exposure = args.scene.auto_exposure;
  if (!args.scene.default_rig.empty()) {
    std::string rig;
    for (const auto& light : args.scene.default_rig) rig += " --light " + light;
    // On stdout with the viewer's other news: stderr is for the one line of a failure.
    std::printf("view: no --light or --env: the default rig (key, fill, rim):%s\n", rig.c_str());
    std::fflush(stdout);
  }
  // The window may stay open for hours: say the scene's warnings now, not when it closes.
  commit_pending_outputs();
  const int status = render::run_viewer(options);
  if (status != 0) std::exit(status);
#else
  (void)args;
  throw Error("view: this lucent was built without the window (LUCENT_WITH_VIEWER=OFF)");
#endif
}

}  // namespace

void register_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArguments>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Preview a material on a mesh in a window (GLFW; needs an X display, e.g. xvfb-run -a). "
      "Left drag orbits, the wheel zooms, right drag moves a light, S saves a screenshot "
      "(lucent_view_NNN.png; the image without the panel), R restarts, H hides the panel, D shows "
      "the difference of the current technique (maps, or sh after its best scale) against the last "
      "CPU reference of the same view, Esc quits. The panel "
      "(scaled to the window) switches the material (library or file, reloaded when the file "
      "changes), technique (maps, sh, hierarchical, fur on --mesh tile with L for the seed's "
      "rotating lobe light, reference, pathtrace) and model, edits the material (per channel mean "
      "free path and albedo, "
      "eta, g), and has sliders for N, M, q, K, W_s, W_l, T, exposure, object size and the "
      "deformer.");
  // The reference in the window runs pass after pass at half the window's resolution: fewer
  // samples per pass than `lucent render`'s default keep the first picture quick.
  args->scene.options.reference.surface_samples = 20000;
  args->scene.options.reference.pixel_samples = 64;
  args->scene.options.pathtrace.pixel_samples = 4;
  args->scene.size = "960x720";
  add_scene_options(cmd, args->scene, "window size WxH in pixels (N: N x N)");
  cmd->add_option("--deform", args->deform,
                  "sine deformer: amplitude as a fraction of the bounding-box diagonal (0 = off, "
                  "at most 0.2); the mesh moves every frame and the maps restart with it")
      ->capture_default_str();
  cmd->add_flag("--hide-panel", args->hide_panel, "start without the panel (H shows it)");
  cmd->add_option("--frame-budget-ms", args->frame_budget_ms,
                  "maps: the time a display frame may take (ms): the knobs not given (K, W_s, "
                  "W_l, N, T) climb from a coarse level to the requested ones as each converges, "
                  "each frame split across display frames to keep within it, at a lower "
                  "resolution while it refines if the final pass alone is over 40% of it; 0: the "
                  "knobs as given, whole frames, whatever a frame costs")
      ->check(number_in(0, 1e6, "ms", false))
      ->capture_default_str();
  cmd->add_option(
      "--script", args->script,
      "actions, one per frame, separated by ';': orbit DX DY, light DX DY (pixels), "
      "zoom STEPS, set NAME VALUE (N M q K Ws Wl T exposure size deform technique "
      "model), key LETTER, wait FRAMES, sleep SECONDS, settle (until the maps converge or the "
      "reference has a pass), screenshot FILE.png, panel on|off, difference on|off, restart, "
      "quit");
  cmd->callback([cmd, args] {
    args->fixed = given_maps_knobs(cmd);
    run_view(*args);
  });
}

}  // namespace lucent::cli
