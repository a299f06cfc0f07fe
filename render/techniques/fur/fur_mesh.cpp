// Fur shells over a mesh, the extension of Klotzli & Olano (render_fur_mesh in
// render/include/lucent/render/fur_renderer.h): the skin from the radiance maps under the coat's
// transmittance (fur_coat.h), then the shells (fur_mesh.vert / .frag) alpha-blended over it.
#include <chrono>
#include <cmath>

#include "fur_gl.h"
#include "gl_frame.h"
#include "gl_program.h"
#include "lucent/core/error.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/radiance_maps.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {

namespace {

double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

gl::Buffer storage(const void* data, std::size_t bytes) {
  gl::Buffer b = gl::create_buffer();
  glNamedBufferStorage(b.id(), GLsizeiptr(std::max<std::size_t>(bytes, 4)), data, 0);
  return b;
}

// Per vertex: the lights' SH in its frame at the coat's middle, 3 channels x 7 vec4
// (coefficients 4k..4k+3).
std::vector<float> vertex_light_sh(const Scene& scene, const fur::FurOptions& o) {
  const Mesh& mesh = scene.mesh;
  const std::size_t V = mesh.positions.size();
  std::vector<float> light(V * 84, 0.0f);
  const float lift = 0.5f * float(o.height_mm);  // the coat's middle
  for (std::size_t v = 0; v < V; ++v) {
    const Vec3f n = mesh.normals[v].normalized();
    const auto c = fur_light_sh(scene.lights, mesh.positions[v] + lift * n, fur_vertex_frame(n));
    for (int ch = 0; ch < 3; ++ch)
      for (int i = 0; i < kShCoefficients; ++i)
        light[v * 84 + std::size_t(ch) * 28 + std::size_t(i)] =
            float(c[std::size_t(ch)][std::size_t(i)]);
  }
  return light;
}

// `image` as an RGBA32F texture, rows bottom-up as GL stores them (alpha 1).
gl::Texture upload_image(const ImageRgb& image) {
  const int W = image.width, H = image.height;
  std::vector<float> rgba(std::size_t(W) * H * 4, 1.0f);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c)
        rgba[(std::size_t(H - 1 - y) * W + x) * 4 + std::size_t(c)] = image.at(x, y, c);
  gl::Texture texture = gl::create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(texture.id(), 1, GL_RGBA32F, W, H);
  glTextureSubImage2D(texture.id(), 0, 0, 0, W, H, GL_RGBA, GL_FLOAT, rgba.data());
  return texture;
}

}  // namespace

ImageRgb render_fur_mesh(const Scene& scene, const fur::FurOptions& options,
                         const RenderSettings& skin_settings, RenderStats* stats,
                         const SkinRenderer& skin_renderer) {
  const double t0 = now_ms();
  const Mesh& mesh = scene.mesh;
  if (mesh.triangles.empty()) throw Error("--technique fur: the mesh has no triangles");
  if (mesh.normals.size() != mesh.positions.size()) {
    throw Error("--technique fur: the mesh needs one normal per vertex");
  }
  if (scene.lights.empty()) throw Error("--light: the fur technique needs at least one light");
  const fur::FurOptions o = fur::over_mesh(options);
  const fur::FurTile tile = fur::make_fur_tile(o);
  Scene skin_scene = scene;
  if (!skin_scene.fur_coat) skin_scene.fur_coat = fur::coat_transmittance(tile, o.optical_density);
  const double precompute_ms = now_ms() - t0;

  // The skin: the BSSRDF under the coat (its own headless context, closed on return).
  const double t_skin = now_ms();
  const ImageRgb skin =
      skin_renderer ? skin_renderer(skin_scene) : render_radiance_maps(skin_scene, skin_settings);
  const double skin_ms = now_ms() - t_skin;

  const auto context = GlContext::create_headless();
  const int W = scene.camera.width, H = scene.camera.height;
  const std::size_t V = mesh.positions.size();
  const std::vector<float> light = vertex_light_sh(scene, o);
  std::vector<unsigned> indices;
  indices.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
  const gl::Buffer positions = storage(mesh.positions.data(), V * sizeof(Vec3f));
  const gl::Buffer normals = storage(mesh.normals.data(), V * sizeof(Vec3f));
  const gl::Buffer index_buffer = storage(indices.data(), indices.size() * sizeof(unsigned));
  const gl::Buffer light_buffer = storage(light.data(), light.size() * sizeof(float));
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));

  const gl::Texture transfer = detail::upload_fur_transfer(tile);
  const gl::Sampler sampler = detail::fur_sampler();
  const gl::Texture skin_texture = upload_image(skin);

  const gl::Program program({{GL_VERTEX_SHADER, "fur_mesh.vert"}, {GL_FRAGMENT_SHADER, "fur_mesh.frag"}});
  const gl::Program blit({{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "image_blit.frag"}});
  const gl::VertexArray vao = gl::create_vertex_array();
  gl::FinalTarget target;  // bare: the skin image is its background
  target.resize(W, H);

  const float spacing_mm = float(o.height_mm) / float(o.shells);
  const detail::Mat4f view_proj =
      detail::camera_view_proj(scene.camera, mesh.centre(), mesh.bounding_radius() + float(o.height_mm));
  const Vec3f albedo = detail::fur_albedo(scene.material);
  glProgramUniformMatrix4fv(program.id(), program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glProgramUniform1f(program.id(), program.location("u_spacing_mm"), spacing_mm);
  glProgramUniform1f(program.id(), program.location("u_tile_mm"), float(o.tile_mm));
  glProgramUniform3fv(program.id(), program.location("u_albedo"), 1, albedo.data());
  glProgramUniform1i(program.id(), program.location("u_transfer"), 0);
  glProgramUniform1i(blit.id(), blit.location("u_image"), 1);

  double draw_ms = 0;
  for (int frame = 0; frame < 2; ++frame) {  // the first compiles shaders on llvmpipe
    const double t_draw = now_ms();
    target.bind();
    glBindVertexArray(vao.id());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    blit.use();
    glBindTextureUnit(1, skin_texture.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    program.use();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, positions.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, normals.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, index_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, light_buffer.id());
    glBindTextureUnit(0, transfer.id());
    glBindSampler(0, sampler.id());
    // The mesh's depth (no colour), then the shells inner to outer (back to front on the side
    // facing the camera; back faces culled, so the far side's shells do not show through).
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glUniform1i(program.location("u_depth_only"), 1);
    const GLsizei corners = GLsizei(indices.size());
    glDrawArraysInstanced(GL_TRIANGLES, 0, corners, 1);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glUniform1i(program.location("u_depth_only"), 0);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glDrawArraysInstanced(GL_TRIANGLES, 0, corners, o.shells);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_TRUE);
    glFinish();
    draw_ms = now_ms() - t_draw;
  }
  gl::check_errors("fur over a mesh");
  ImageRgb image = target.read_image();
  if (stats != nullptr) {
    stats->technique = "fur";
    stats->width = W;
    stats->height = H;
    stats->total_ms = now_ms() - t0;
    stats->pass_ms = {{"precompute", precompute_ms}, {"skin (maps)", skin_ms}, {"draw", draw_ms}};
    stats->details = {{"texels", o.texels},
                      {"shells", o.shells},
                      {"hairs", o.overcoat.hairs + o.undercoat.hairs},
                      {"tile_mm", o.tile_mm},
                      {"height_mm", o.height_mm},
                      {"coat_T(1)", skin_scene.fur_coat->at(1.0)},
                      {"coat_T(0.5)", skin_scene.fur_coat->at(0.5)},
                      {"timing", "draw: the second frame of the shells, glFinish and wall clock"}};
  }
  return image;
}

}  // namespace lucent::render
