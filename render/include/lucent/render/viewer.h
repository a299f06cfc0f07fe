// `lucent view`: the material preview window (GLFW + Dear ImGui, OpenGL 4.5 core). The radiance
// maps accumulate while nothing changes and restart when something does; the CPU reference can be
// switched in (progressive passes on worker threads, shown as they finish), and so can the SH fast
// translucency (Banterle & Chalmers: every pass every frame, nothing accumulated). The difference
// view (D) holds the current technique against the cached reference of the same view (sh after its
// least-squares scale: it is not physically based).
//
// Controls: left drag orbits, the wheel zooms, right drag moves the selected light around the
// object; S saves a screenshot (lucent_view_NNN.png in the working folder), R restarts the
// accumulation, H hides the panel, E sets the exposure from the image, Esc quits. The panel (docked
// at the left, the image beside it; resizable, foldable) has the material (library or file, the
// file reloaded when it changes; its colour and mean free path, or its coefficients, edited and
// saved), the technique and model, sliders for N, M, q, K, W_s, W_l, T, exposure and object size,
// the sine deformer, per-stage times, the accumulated frames and the quality the frame budget
// chose. Input and the panel are handled every frame; frames are kept within the frame budget
// while the maps refine, and nothing is rendered once they have converged.
#pragma once

#include <chrono>
#include <string>

#include "lucent/render/frame_budget.h"
#include "lucent/render/fur.h"
#include "lucent/render/hierarchical.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/sh_renderer.h"
#include "lucent/render/technique.h"
#include "lucent/render/viewer_controls.h"

namespace lucent::render {

struct ViewerOptions {
  Scene scene;                     ///< camera width x height = the window's initial size
  std::string material_source;     ///< library name or file path (a file is watched and reloaded)
  RenderSettings settings;         ///< the radiance-map knobs and the model
  bool model_follows_material = true;  ///< no --model: a newly chosen material brings its model
  ReferenceOptions reference;      ///< surface samples per pass, threads and seed for the reference
  PathTraceOptions pathtrace;      ///< paths per pixel per pass for the path tracer
  OrbitView view;                  ///< --view
  double object_size_mm = 100;     ///< the mesh's bounding-box diagonal as loaded
  TechniqueId technique = TechniqueId::kMaps;
  hierarchical::Options hierarchical;  ///< --technique hierarchical: oracle, form factor, mode
  ShOptions sh;                    ///< --technique sh: shadow map, cube map, depth blur, Fresnel
  fur::FurOptions fur;             ///< --technique fur: the tile (--mesh tile)
  float deform_amplitude = 0;      ///< sine deformer: fraction of the diagonal; 0 = off
  /// Actions, one per frame, separated by ';' (tests and demos drive the window with them):
  ///   orbit DX DY | light DX DY   mouse drags in pixels (left button / right button)
  ///   zoom STEPS                  scroll-wheel steps (up = closer)
  ///   set NAME VALUE              the CLI's flag without dashes: maps-samples, maps-disc-points,
  ///                               maps-q, maps-directions, maps-radiance-map, maps-light-map,
  ///                               maps-frames, maps-disc-selection, technique, model, exposure,
  ///                               object-size-mm, deform; and light_scale (the panel's N, M, q,
  ///                               K, Ws, Wl, T, disc, size still work)
  ///   key LETTER                 a key press (S, R, H, D)
  ///   panel on|off | difference on|off   the panel; the difference view against the reference
  ///   screenshot-panel FILE.png   a screenshot with the panel (`screenshot` leaves it out)
  ///   wait FRAMES | sleep SECONDS
  ///   settle                      until the maps converge or the reference has a pass (<= 300 s)
  ///   screenshot FILE.png | restart | quit
  std::string script;
  bool hide_panel = false;     ///< --hide-panel: start without the panel (H toggles it)
  /// --frame-budget-ms: the maps climb the quality ladder of the knobs not in `fixed`
  /// (frame_budget.h) from the coarsest level to the requested settings, a level as the one below
  /// converges, each frame split across display frames so that none takes much longer than this,
  /// and the image rendered at a lower resolution while it refines when the final pass alone
  /// takes over 40% of it; 0: the knobs as given, whole frames, whatever a frame costs.
  double frame_budget_ms = 50;
  FixedKnobs fixed;            ///< the maps' knobs given on the command line (and then the panel's)
  /// When the command started (the summary's "first image after S s").
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  bool auto_exposure = false;  ///< --exposure auto: set once from the first images (tone_map.h)
};

/// Opens the window and runs until it is closed (or the script quits). Returns the exit status.
/// Throws lucent::Error when no window or OpenGL 4.5 context can be made, or on a bad script.
int run_viewer(const ViewerOptions& options);

}  // namespace lucent::render
