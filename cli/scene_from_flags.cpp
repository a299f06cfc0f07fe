// lucent.render's scene from `lucent render`'s flags (scene_from_flags.h).
#include "scene_from_flags.h"

#include <algorithm>

#include "lucent/core/error.h"
#include "scene_options.h"

namespace lucent::cli {

FlagScene scene_from_flags(const std::vector<std::string>& flags) {
  CLI::App app("lucent.render");
  SceneArguments args;
  add_scene_options(&app, args, "image size WxH in pixels (N: N x N)");
  std::vector<std::string> reversed(flags.rbegin(), flags.rend());  // CLI11 takes them backwards
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw Error(e.what());
  }
  FlagScene out;
  out.scene = build_scene(args).scene;
  out.technique = args.technique_id;
  out.options = args.options;
  return out;
}

bool is_scene_flag(const std::string& flag) {
  CLI::App app("lucent.render");
  SceneArguments args;
  add_scene_options(&app, args, "");
  return app.get_option_no_throw(flag) != nullptr;
}

}  // namespace lucent::cli
