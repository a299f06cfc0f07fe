// The options `lucent render` and `lucent view` share (material, mesh, lights, environment, camera,
// technique, the radiance-map knobs and the reference's), and the Scene they describe. Everything
// that needs no file is validated first, so that typing errors fail before any loading.
#pragma once

#include <functional>
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
  double crease_angle_deg = render::kDefaultCreaseAngleDeg;  ///< --crease-angle
  std::string exposure = "auto";  ///< a number or auto (tone_map.h auto_exposure)
  bool auto_exposure = true;      ///< set by build_scene from `exposure`
  float roughness = 0.1f;
  std::string specular = "on";
  std::string single_scattering = "auto";  ///< --single-scattering auto|on|off
  std::string angular = "on";              ///< --angular on|off
  std::string geometry_factor = "on";      ///< --geometry-factor on|off
  std::string backdrop;                  ///< R,G,B radiance; empty: black
  std::string ground = "off";            ///< --ground off|on|R,G,B albedo
  std::vector<std::string> default_rig;  ///< set by build_scene: the lights used when none given
  /// Every technique's options, filled by their flag groups (technique_flags.h); --seed writes
  /// options.reference.seed, build_scene the model and the exposure into options.settings.
  render::TechniqueOptions options;
  std::string fur_coat = "off";    ///< --fur-coat on|off: a fur coat over the skin (fur_coat.h)
  /// Called by build_scene once everything is validated and loaded: the deprecation line of the
  /// earlier spellings (technique_flags.h), so that a refusal stays one line.
  std::function<void()> on_valid;
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
