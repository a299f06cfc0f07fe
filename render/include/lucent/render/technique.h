// The techniques lucent renders with, in one registry: each one's name (the CLI's --technique
// value, and the prefix of its files and flags), what it is (physically based or right only up to a
// scale, the diffusion models it integrates, whether it needs OpenGL, whether it takes a fur coat
// or converges frame by frame), the one place where a technique is chosen by its name, and the
// factory of the frame-by-frame ones (technique_base.h). Adding a technique is its folder plus one
// line in technique.cpp's table and one case in render_still.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lucent/materials/profile_table.h"
#include "lucent/render/frame_budget.h"
#include "lucent/render/fur.h"
#include "lucent/render/hierarchical.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/sh_renderer.h"
#include "lucent/render/technique_base.h"

namespace lucent::render {

struct TechniqueInfo {
  TechniqueId id;
  std::string name;   ///< --technique's value: maps, sh, hierarchical, fur, reference
  std::string label;  ///< for people: "radiance maps", "CPU reference", ...
  std::string panel_label;  ///< the viewer's radio button: "SH fast", ...
  std::string help;   ///< its clause in --technique's help
  /// False where the images are right only up to a scale (compare them after the best scale).
  bool physically_based = true;
  /// The diffusion models it integrates; `model_note` says why where it is one only.
  std::vector<materials::DiffusionModel> models;
  std::string model_note;
  bool gpu = true;               ///< needs an OpenGL 4.5 context
  bool fur_coat = true;          ///< renders a fur coat over the skin (--fur-coat on)
  bool frame_snapshots = false;  ///< converges frame by frame and writes snapshots (--snapshots)
  /// Makes the technique's frame-by-frame renderer (technique_base.h); null for the CPU reference,
  /// which renders stills only.
  std::unique_ptr<Technique> (*make)() = nullptr;
  /// Adds the single-scattering term (Scene::single_scattering) beside its multiple scattering;
  /// the path tracer's transport always holds it.
  bool single_scattering = false;

  bool supports(materials::DiffusionModel model) const;
};

/// Every technique, in the order the help and the viewer list them.
const std::vector<TechniqueInfo>& techniques();
const TechniqueInfo& technique_info(TechniqueId id);
/// The technique called `name`, or nullptr.
const TechniqueInfo* find_technique(std::string_view name);
/// The technique called `name`; lucent::Error "OPTION: expected maps, sh, hierarchical, fur or
/// reference, got 'NAME'" otherwise.
TechniqueId parse_technique(std::string_view name, const std::string& option = "--technique");
/// "maps, sh, hierarchical, fur or reference": the names of the techniques `which` accepts (all when
/// it is empty).
std::string technique_names(const std::function<bool(const TechniqueInfo&)>& which = {});

/// A new, not yet set up, frame-by-frame renderer of technique `id`; std::logic_error for one
/// without (the reference).
std::unique_ptr<Technique> make_technique(TechniqueId id);

/// Every technique's options, as `lucent render` fills them; each technique reads its own (and the
/// maps' settings carry the model and the exposure every technique uses).
struct TechniqueOptions {
  RenderSettings settings;
  RadianceMapOptions maps;
  ShOptions sh;
  hierarchical::Options hierarchical;
  fur::FurOptions fur;
  ReferenceOptions reference;
  PathTraceOptions pathtrace;
};

/// One still image of `scene` by technique `id`: linear RGB radiance, camera.width x camera.height,
/// row 0 at the top. Fills `stats` when given.
ImageRgb render_still(TechniqueId id, const Scene& scene, const TechniqueOptions& options,
                      RenderStats* stats);

/// The reference or the path tracer within `budget_s` seconds (infinity: all it was asked for):
/// their samples (per pixel; the reference's area sampling: on the surface) times passes, split
/// by run_sample_budget into passes of their own seeds, averaged weighted by their samples.
/// `on_image(mean so far, pass, samples so far)` after every pass (the first: the coarse image);
/// `progress(share)` the larger of the samples' and the budget's share. std::logic_error for
/// another technique.
struct BudgetedStill {
  ImageRgb image;
  SampleBudgetRun run;
  int requested = 0;  ///< the samples asked for (per pass times passes)
};
BudgetedStill render_still_within_budget(
    TechniqueId id, const Scene& scene, const TechniqueOptions& options, double budget_s,
    const std::function<void(const ImageRgb& image, int pass, int samples)>& on_image,
    const std::function<void(double share)>& progress, RenderStats* stats);

/// The options technique `id` was run with, as text (the render statistics' "settings").
std::string settings_text(TechniqueId id, const TechniqueOptions& options);

}  // namespace lucent::render
