// The options `lucent render` and `lucent view` share (material, mesh, lights, environment, camera,
// technique, the radiance-map knobs and the reference's), and the Scene they describe. Everything
// that needs no file is validated first, so that typing errors fail before any loading.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lucent/render/fur.h"
#include "lucent/render/hierarchical.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/sh_renderer.h"
#include "lucent/render/technique.h"

namespace lucent::cli {

struct SceneArguments {
  std::string material;
  std::string mesh = "sphere";
  std::vector<std::string> lights;
  std::string env;
  std::string technique = "maps";                                 ///< --technique as typed
  render::TechniqueId technique_id = render::TechniqueId::kMaps;  ///< set by build_scene
  std::string model;
  std::string view = "30,20,3.4";  // 3.4 radii: the bounding sphere fits the 35-degree view
  std::string size;
  double object_size_mm = 100;
  std::string disc_selection = "strata";
  std::string disc_distribution = "profile";
  std::string reference_sampling = "probes";
  std::string exposure = "auto";  ///< a number or auto (tone_map.h auto_exposure)
  bool auto_exposure = true;      ///< set by build_scene from `exposure`
  float roughness = 0.1f;
  std::string specular = "on";
  std::string irradiance_cache = "off";  // --irradiance-cache on|off (reference)
  std::string hbe_irradiance_cache = "on";  // --hbe-irradiance-cache on|off
  std::string backdrop;           ///< R,G,B radiance; empty: black
  int max_blur = -1;              ///< maps: RadianceMapOptions::max_blur_level (-1 automatic)
  std::vector<std::string> default_rig;  ///< set by build_scene: the lights used when none given
  render::RenderSettings settings;
  render::ReferenceOptions reference;
  render::ShOptions sh;            ///< --technique sh: shadow map, cube map, depth blur, Fresnel
  std::string sh_fresnel = "exact";  ///< exact | schlick
  std::string sh_attenuation = "slab";  ///< seed | normalised | slab
  render::hbe::Options hbe;        ///< --technique hierarchical: oracle, form factor, mode
  render::fur::FurOptions fur;     ///< --technique fur: the tile; --fur-coat: the coat's hairs
  std::string fur_coat = "off";    ///< --fur-coat on|off: a fur coat over the skin (fur_coat.h)
  std::string fur_coverage = "exact";  ///< --fur-coverage exact|seed: the hairs' cross-sections
  std::string hbe_mode = "render", hbe_rule = "gauss2", hbe_dipole = "chord";
};

/// Adds the shared options to `cmd`; `size_help` says what --size is (image or window).
void add_scene_options(CLI::App* cmd, SceneArguments& args, const std::string& size_help);

struct SceneSetup {
  render::Scene scene;  ///< camera from --view and --size; material loaded; lights incl. --env's
  float azimuth_deg = 0, elevation_deg = 0, distance_radii = 0;  ///< --view
};

/// Validates the arguments (one lucent::Error naming the option on the first bad one), then loads
/// the material, mesh and environment. Sets args.settings.model from --model or the material.
SceneSetup build_scene(SceneArguments& args);

}  // namespace lucent::cli
