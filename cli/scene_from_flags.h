// lucent.render's way into `lucent render`'s options (no CLI11 here): the scene and technique flags
// as strings, parsed and checked by the same CLI11 options, to the scene and the technique's
// options.
#pragma once

#include <string>
#include <vector>

#include "lucent/render/scene.h"
#include "lucent/render/technique.h"

namespace lucent::cli {

struct FlagScene {
  render::Scene scene;
  render::TechniqueId technique = render::TechniqueId::kMaps;
  render::TechniqueOptions options;
};

/// `flags` as `lucent render` takes them ("--material", "marble", "--size", "64x48", ...; its own
/// -o and --budget aside): one lucent::Error naming the flag on the first bad one (CLI11's parse
/// errors included), else the scene loaded.
FlagScene scene_from_flags(const std::vector<std::string>& flags);

/// Whether `flag` ("--maps-directions") is one of those options.
bool is_scene_flag(const std::string& flag);

}  // namespace lucent::cli
