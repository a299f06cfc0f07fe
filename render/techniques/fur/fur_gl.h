// The GL pieces the fur tile (fur_renderer.cpp) and fur over a mesh (fur_mesh.cpp) share.
#pragma once

#include "gl_api.h"
#include "gl_program.h"
#include "lucent/materials/material.h"
#include "lucent/render/fur.h"
#include "lucent/render/scene.h"

namespace lucent::render::detail {

/// The tile's transfer as a 2D array texture (RGBA32F): 7 layers per shell, layer 7 s + k holding
/// t_4k..t_4k+3, layer 7 s + 6 t_24 in x and the shell's hair coverage in y (fur_shade.glsl).
gl::Texture upload_fur_transfer(const fur::FurTile& tile);

/// Bilinear, repeating (the tile wraps).
gl::Sampler fur_sampler();

/// The hairs' colour: the material's reduced albedo per channel.
Vec3f fur_albedo(const materials::Material& material);

}  // namespace lucent::render::detail
