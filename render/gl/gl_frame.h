// GL pieces every real-time technique shares (radiance maps, sh): the mesh's vertex buffers, the
// environment map as a texture, the background and present passes, and reading the final RGBA
// target back as an image and a mask. Needs a current GL context.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "gl_api.h"
#include "gl_program.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"

namespace lucent::render::gl {

/// A mesh on the GPU: positions at attribute 0, normals at 1 (both writable, for deforming
/// meshes), indexed triangles.
struct MeshBuffers {
  VertexArray vao;
  Buffer positions, normals, indices;
  GLsizei index_count = 0;

  void draw() const;                          ///< glDrawElements of every triangle
  void draw_instanced(GLsizei count) const;   ///< the same, `count` instances
};

MeshBuffers upload_mesh(const Mesh& mesh);

/// New positions (mm) and normals for the same vertices; throws lucent::Error naming `who` when
/// the counts differ from `mesh`'s.
void update_mesh(MeshBuffers& buffers, const Mesh& mesh, const std::vector<Vec3f>& positions,
                 const std::vector<Vec3f>& normals, const char* who);

/// The lat-long environment map as an RGB32F texture (row 0, theta = 0, at t = 0).
Texture upload_environment(const std::filesystem::path& path);

/// background.frag over the whole viewport: the environment seen through `view_proj` when
/// `environment` is non-zero (bound to `unit` with `sampler`), else `backdrop`.
void draw_background(const Program& background, const Eigen::Matrix4f& view_proj,
                     GLuint environment, GLuint sampler, GLuint unit, const Vec3f& backdrop,
                     GLuint empty_vao);

/// present.frag: `image` tone-mapped with `exposure` into the bound draw framebuffer.
void draw_present(const Program& present, GLuint image, GLuint sampler, GLuint empty_vao,
                  float exposure, int width, int height);

/// The RGBA32F level 0 of `texture`, width x height, rows from the bottom (GL's order).
std::vector<float> read_rgba(GLuint texture, int width, int height);
/// RGB of an RGBA read-back, rows flipped so that row 0 is the top.
ImageRgb image_from_rgba(const std::vector<float>& rgba, int width, int height);
/// 1 where alpha > 0, rows flipped as image_from_rgba.
std::vector<std::uint8_t> mask_from_rgba(const std::vector<float>& rgba, int width, int height);

}  // namespace lucent::render::gl
