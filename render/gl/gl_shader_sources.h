// The shader files of render/gl/shaders and render/techniques/*/shaders, embedded as string
// constants by a build step (render/gl_sources.cmake generates gl_shader_sources.cpp, which defines
// embedded_shaders()).
#pragma once

#include <span>
#include <string_view>

namespace lucent::render::gl {

struct EmbeddedShader {
  std::string_view name;  ///< file name, e.g. "radiance_map.frag"
  std::string_view text;  ///< its contents
};

std::span<const EmbeddedShader> embedded_shaders();

}  // namespace lucent::render::gl
