// The OpenGL driver's shader cache for `render` and `view`: on llvmpipe compiling the maps'
// programs at their first draws is most of the time to the first image (1.8 s of `view`'s first
// image at 640 x 480 on a cold cache, 0.7 s warm), so a cache in lucent's own cache folder
// (the data cache's mesa-shaders/) is used unless the person set Mesa's variables; where that
// folder cannot be written the cache is off (a read-only home). No CLI11 here.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "lucent/render/scene.h"

namespace lucent::cli {

inline void use_shader_cache() {
  if (std::getenv("MESA_SHADER_CACHE_DISABLE") || std::getenv("MESA_SHADER_CACHE_DIR")) return;
  const std::filesystem::path dir = render::data_cache_dir() / "mesa-shaders";
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (!error && ::access(dir.c_str(), W_OK) == 0) {
    setenv("MESA_SHADER_CACHE_DIR", dir.c_str(), 0);
  } else {
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  }
}

}  // namespace lucent::cli
