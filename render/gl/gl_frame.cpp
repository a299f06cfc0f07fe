// Shared GL pieces of the real-time techniques (gl_frame.h).
#include "gl_frame.h"

#include <string>

#include "lucent/core/error.h"
#include "lucent/render/environment.h"

namespace lucent::render::gl {

void MeshBuffers::draw() const {
  glBindVertexArray(vao.id());
  glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
}

void MeshBuffers::draw_instanced(GLsizei count) const {
  glBindVertexArray(vao.id());
  glDrawElementsInstanced(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr, count);
}

MeshBuffers upload_mesh(const Mesh& m) {
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  MeshBuffers b;
  b.vao = create_vertex_array();
  b.positions = create_buffer();
  b.normals = create_buffer();
  b.indices = create_buffer();
  // Positions and normals stay writable: a deforming mesh replaces them every frame.
  glNamedBufferStorage(b.positions.id(), GLsizeiptr(m.positions.size() * sizeof(Vec3f)),
                       m.positions.data(), GL_DYNAMIC_STORAGE_BIT);
  glNamedBufferStorage(b.normals.id(), GLsizeiptr(m.normals.size() * sizeof(Vec3f)),
                       m.normals.data(), GL_DYNAMIC_STORAGE_BIT);
  glNamedBufferStorage(b.indices.id(), GLsizeiptr(m.triangles.size() * sizeof(m.triangles[0])),
                       m.triangles.data(), 0);
  b.index_count = GLsizei(m.triangles.size() * 3);
  const GLuint vao = b.vao.id();
  glVertexArrayVertexBuffer(vao, 0, b.positions.id(), 0, sizeof(Vec3f));
  glVertexArrayVertexBuffer(vao, 1, b.normals.id(), 0, sizeof(Vec3f));
  glVertexArrayElementBuffer(vao, b.indices.id());
  for (GLuint a = 0; a < 2; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, a, a);
  }
  return b;
}

void update_mesh(MeshBuffers& b, const Mesh& mesh, const std::vector<Vec3f>& positions,
                 const std::vector<Vec3f>& normals, const char* who) {
  if (positions.size() != mesh.positions.size() || normals.size() != mesh.positions.size()) {
    throw Error(std::string(who) + ": a deformed mesh needs " +
                std::to_string(mesh.positions.size()) + " vertices (got " +
                std::to_string(positions.size()) + " positions, " +
                std::to_string(normals.size()) + " normals)");
  }
  glNamedBufferSubData(b.positions.id(), 0, GLsizeiptr(positions.size() * sizeof(Vec3f)),
                       positions.data());
  glNamedBufferSubData(b.normals.id(), 0, GLsizeiptr(normals.size() * sizeof(Vec3f)),
                       normals.data());
}

Texture upload_environment(const std::filesystem::path& path) {
  const EnvironmentMap map = load_environment(path);
  Texture t = create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(t.id(), 1, GL_RGB32F, map.image.width, map.image.height);
  // Row 0 (the top, theta = 0) goes to t = 0, so v = theta / pi reads it directly.
  glTextureSubImage2D(t.id(), 0, 0, 0, map.image.width, map.image.height, GL_RGB, GL_FLOAT,
                      map.image.data.data());
  return t;
}

void draw_background(const Program& background, const Eigen::Matrix4f& view_proj,
                     GLuint environment, GLuint sampler, GLuint unit, const Vec3f& backdrop,
                     GLuint empty_vao) {
  glDisable(GL_DEPTH_TEST);
  background.use();
  const Eigen::Matrix4f inverse = view_proj.inverse();
  glUniformMatrix4fv(background.location("u_inverse_view_proj"), 1, GL_FALSE, inverse.data());
  glUniform1i(background.location("u_has_environment"), environment != 0 ? 1 : 0);
  glUniform3fv(background.location("u_backdrop"), 1, backdrop.data());
  if (environment != 0) {
    glBindTextureUnit(unit, environment);
    glBindSampler(unit, sampler);
  }
  glBindVertexArray(empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void draw_present(const Program& present, GLuint image, GLuint sampler, GLuint empty_vao,
                  float exposure, int x, int y, int width, int height) {
  glViewport(x, y, width, height);
  glDisable(GL_DEPTH_TEST);
  present.use();
  glUniform1f(present.location("u_exposure"), exposure);
  glBindTextureUnit(0, image);
  glBindSampler(0, sampler);
  glBindVertexArray(empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

std::vector<float> read_rgba(GLuint texture, int width, int height) {
  std::vector<float> rgba(std::size_t(width) * std::size_t(height) * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)),
                    rgba.data());
  return rgba;
}

ImageRgb image_from_rgba(const std::vector<float>& rgba, int width, int height) {
  ImageRgb image(width, height);
  for (int y = 0; y < height; ++y) {
    const std::size_t row = std::size_t(height - 1 - y);  // GL rows go up from the bottom
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) = rgba[(row * std::size_t(width) + std::size_t(x)) * 4 + std::size_t(c)];
      }
    }
  }
  return image;
}

std::vector<std::uint8_t> mask_from_rgba(const std::vector<float>& rgba, int width, int height) {
  std::vector<std::uint8_t> mask(std::size_t(width) * std::size_t(height));
  for (int y = 0; y < height; ++y) {
    const std::size_t row = std::size_t(height - 1 - y);
    for (int x = 0; x < width; ++x) {
      mask[std::size_t(y) * std::size_t(width) + std::size_t(x)] =
          rgba[(row * std::size_t(width) + std::size_t(x)) * 4 + 3] > 0 ? 1 : 0;
    }
  }
  return mask;
}

namespace {
Sampler bilinear_sampler(GLint wrap_s) {
  Sampler s = create_sampler();
  glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, wrap_s);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return s;
}
}  // namespace

void FinalTarget::build(const Scene& scene, int width, int height, GLuint environment_unit,
                        bool with_environment) {
  background_ =
      Program({{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "background.frag"}});
  present_ = Program({{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "present.frag"}});
  environment_unit_ = environment_unit;
  glProgramUniform1i(background_.id(), background_.location("u_environment"),
                     GLint(environment_unit));
  glProgramUniform1i(present_.id(), present_.location("u_image"), 0);
  linear_ = bilinear_sampler(GL_CLAMP_TO_EDGE);
  environment_sampler_ = bilinear_sampler(GL_REPEAT);
  empty_vao_ = create_vertex_array();
  environment_ = Texture();
  if (with_environment && scene.environment) environment_ = upload_environment(*scene.environment);
  resize(width, height);
}

void FinalTarget::resize(int width, int height) {
  if (width < 1 || height < 1) throw Error("--size: the image has no pixels");
  width_ = width;
  height_ = height;
  color_ = create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(color_.id(), 1, GL_RGBA32F, width, height);
  depth_ = create_renderbuffer();
  glNamedRenderbufferStorage(depth_.id(), GL_DEPTH_COMPONENT32F, width, height);
  fbo_ = create_framebuffer();
  glNamedFramebufferTexture(fbo_.id(), GL_COLOR_ATTACHMENT0, color_.id(), 0);
  glNamedFramebufferRenderbuffer(fbo_.id(), GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.id());
  check_framebuffer(fbo_.id(), "the final image");
}

void FinalTarget::bind() const {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_.id());
  glViewport(0, 0, width_, height_);
  const float one = 1.0f;
  glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &one);
}

void FinalTarget::begin_frame(const Eigen::Matrix4f& view_proj, const Vec3f& backdrop) const {
  bind();
  draw_background(background_, view_proj, environment_.id(), environment_sampler_.id(),
                  environment_unit_, backdrop, empty_vao_.id());
}

void FinalTarget::present(float exposure, int x, int y, int width, int height) const {
  draw_present(present_, color_.id(), linear_.id(), empty_vao_.id(), exposure, x, y, width, height);
}

std::vector<float> FinalTarget::read_rgba() const {
  return gl::read_rgba(color_.id(), width_, height_);
}

ImageRgb FinalTarget::read_image() const {
  return image_from_rgba(read_rgba(), width_, height_);
}

std::vector<std::uint8_t> FinalTarget::read_mask() const {
  return mask_from_rgba(read_rgba(), width_, height_);
}

}  // namespace lucent::render::gl
