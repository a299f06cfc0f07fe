// GL pieces every real-time technique shares: the mesh's vertex buffers and the final target (the
// image a technique draws and shows, with the environment, the background, the present pass and
// the read-back around it). Needs a current GL context.
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
                  float exposure, int x, int y, int width, int height);

/// The RGBA32F level 0 of `texture`, width x height, rows from the bottom (GL's order).
std::vector<float> read_rgba(GLuint texture, int width, int height);
/// RGB of an RGBA read-back, rows flipped so that row 0 is the top.
ImageRgb image_from_rgba(const std::vector<float>& rgba, int width, int height);
/// 1 where alpha > 0, rows flipped as image_from_rgba.
std::vector<std::uint8_t> mask_from_rgba(const std::vector<float>& rgba, int width, int height);

/// The image a technique draws and shows, set up once for every technique: an RGBA32F colour
/// texture and a 32-bit float depth renderbuffer of the camera's size in one framebuffer; the
/// scene's environment as a texture (lat-long: bilinear, wrapping in u, clamped in v); and the
/// passes around the technique's own: the background under the object, the tone-mapped present into
/// the window, and the read-back as an image and a mask.
class FinalTarget {
 public:
  /// Programs, samplers, the environment texture when the scene has one and `with_environment`,
  /// then resize(width, height). `environment_unit`: the texture unit the environment stays bound
  /// to after begin_frame, for the technique's own reflections.
  void build(const Scene& scene, int width, int height, GLuint environment_unit,
             bool with_environment = true);
  /// New colour and depth storage of width x height pixels (lucent::Error when empty). Alone,
  /// without build(), a bare target: bind() and the read-backs work, not the passes.
  void resize(int width, int height);
  /// Binds the framebuffer as the draw framebuffer over the whole target and clears its depth.
  void bind() const;

  /// Binds the framebuffer over the whole target, clears its depth, and draws the background seen
  /// through `view_proj`: the environment, else the backdrop colour. Leaves depth testing off.
  void begin_frame(const Eigen::Matrix4f& view_proj, const Vec3f& backdrop) const;
  /// The colour tone-mapped with `exposure` into the bound draw framebuffer, width x height.
  void present(float exposure, int x, int y, int width, int height) const;

  std::vector<float> read_rgba() const;         ///< rows from the bottom (GL's order)
  ImageRgb read_image() const;                  ///< linear RGB, row 0 at the top
  std::vector<std::uint8_t> read_mask() const;  ///< 1 where alpha > 0

  int width() const { return width_; }
  int height() const { return height_; }
  GLuint framebuffer() const { return fbo_.id(); }
  GLuint color() const { return color_.id(); }
  bool has_environment() const { return environment_.id() != 0; }
  GLuint environment() const { return environment_.id(); }
  GLuint environment_sampler() const { return environment_sampler_.id(); }
  GLuint empty_vao() const { return empty_vao_.id(); }

 private:
  Program background_, present_;
  Texture color_, environment_;
  Renderbuffer depth_;
  Framebuffer fbo_;
  Sampler linear_, environment_sampler_;
  VertexArray empty_vao_;
  GLuint environment_unit_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace lucent::render::gl
