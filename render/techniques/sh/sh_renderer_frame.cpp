// The SH technique's frame-by-frame API, the stand-alone GPU projection and render_sh
// (render/include/lucent/render/sh_renderer.h).
#include "lucent/core/error.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/technique.h"
#include "sh_renderer_impl.h"

namespace lucent::render {

ShRenderer::ShRenderer() : impl_(std::make_unique<Impl>()) {}
ShRenderer::~ShRenderer() = default;

void ShRenderer::setup(const Scene& scene, const ShOptions& options) {
  if (scene.fur_coat) {
    throw Error("--fur-coat: the sh technique's precomputed transfer has no fur coat; use maps, "
                "hierarchical or reference");
  }
  const double t0 = now_ms();
  impl_ = std::make_unique<Impl>();
  impl_->build(scene, options);
  glFinish();
  impl_->stats.setup_ms = now_ms() - t0;
}

void ShRenderer::set_camera(const Camera& camera) {
  Impl& m = *impl_;
  if (camera.width != m.width || camera.height != m.height) {
    throw Error("sh: the camera's size cannot change after setup");
  }
  m.scene.camera = camera;
}

void ShRenderer::set_lights(const std::vector<Light>& lights) {
  Impl& m = *impl_;
  if (lights.empty() || int(lights.size()) > kMaxLights) {
    throw Error("--light: the sh technique takes 1.." + std::to_string(kMaxLights) + " lights");
  }
  m.scene.lights = lights;
  m.upload_lights();
}

void ShRenderer::set_material(const materials::Material& material) {
  impl_->scene.material = material;
  impl_->upload_material();
}

void ShRenderer::set_geometry(const std::vector<Vec3f>& positions,
                              const std::vector<Vec3f>& normals) {
  Impl& m = *impl_;
  gl::update_mesh(m.mesh, m.scene.mesh, positions, normals, "sh");
  m.scene.mesh.positions = positions;
  m.scene.mesh.normals = normals;
  m.fit_bounds();
  m.upload_lights();  // the shadow camera is fitted to the new bounds
}

void ShRenderer::set_output(ShOutput output) {
  impl_->output = output;
}

void ShRenderer::setup(const Scene& scene, const TechniqueOptions& options) {
  setup(scene, options.sh);
}

bool ShRenderer::converged() const {
  return impl_->stats.frames > 0;
}

FrameStats ShRenderer::frame_stats() const {
  const ShStats& s = impl_->stats;
  const ShPassTimes& t = s.last_wall;
  FrameStats f;
  f.frames = s.frames;
  f.pass_ms = {{"shadow+peel", t.shadow_ms + t.peel_ms},
               {"depth blur", t.blur_ms},
               {"cube map", t.cube_ms},
               {"SH project", t.project_ms},
               {"final", t.final_ms}};
  f.notes.push_back("primary light " + std::to_string(s.primary_light));
  return f;
}

bool ShRenderer::render_frame() {
  Impl& m = *impl_;
  m.timed(kShadow, [&] { m.shadow_pass(false); });
  m.timed(kPeel, [&] { m.shadow_pass(true); });
  m.timed(kBlur, [&] { m.blur_pass(); });
  m.timed(kCube, [&] { m.cube_pass(); });
  m.timed(kProject, [&] { m.projector->run(m.cube.id(), m.nearest.id()); });
  m.timed(kFinal, [&] { m.final_pass(); });
  ++m.stats.frames;
  gl::check_errors("an sh frame");
  return true;
}

ImageRgb ShRenderer::read_image() const {
  return impl_->final.read_image();
}

std::vector<std::uint8_t> ShRenderer::read_mask() const {
  return impl_->final.read_mask();
}

std::array<std::array<float, 9>, 3> ShRenderer::read_coefficients() const {
  return impl_->projector->read();
}

std::vector<float> ShRenderer::read_cube_map() const {
  const int W = impl_->options.cube_map_size;
  std::vector<float> rgba(std::size_t(W) * std::size_t(W) * 6 * 4);
  glGetTextureImage(impl_->cube.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)),
                    rgba.data());
  return rgba;
}

void ShRenderer::present(float exposure, int x, int y, int width, int height) const {
  impl_->final.present(exposure, x, y, width, height);
}

const ShStats& ShRenderer::stats() const {
  return impl_->stats;
}

std::array<std::array<float, 9>, 3> project_cube_map_on_gpu(const std::vector<float>& rgba,
                                                             int face_size) {
  const std::size_t expected = std::size_t(face_size) * std::size_t(face_size) * 6 * 4;
  if (face_size < 1 || rgba.size() != expected) {
    throw Error("sh: a cube map of " + std::to_string(face_size) + "^2 faces needs " +
                std::to_string(expected) + " floats, got " + std::to_string(rgba.size()));
  }
  gl::Texture cube = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(cube.id(), 1, GL_RGBA32F, face_size, face_size, 6);
  glTextureSubImage3D(cube.id(), 0, 0, 0, 0, face_size, face_size, 6, GL_RGBA, GL_FLOAT,
                      rgba.data());
  const gl::Sampler sampler = make_sampler(GL_NEAREST);
  const Projector projector(face_size);
  projector.run(cube.id(), sampler.id());
  gl::check_errors("sh projection");
  return projector.read();
}

ImageRgb render_sh(const Scene& scene, const ShOptions& options, RenderStats* stats,
                   ShStats* details) {
  const double t0 = now_ms();
  const auto context = GlContext::create_headless();
  ShRenderer renderer;
  renderer.setup(scene, options);
  // One untimed frame first: drivers compile shaders at their first draw (llvmpipe's JIT).
  renderer.render_frame();
  ShStats warm = renderer.stats();
  renderer.render_frame();
  ShStats s = renderer.stats();
  s.frames = 1;
  s.sum_wall = s.last_wall;
  for (int p = 0; p < kPassCount; ++p) {
    pass_field(s.sum_gpu, p) -= pass_field(warm.sum_gpu, p);
  }
  ImageRgb image = renderer.read_image();
  if (details != nullptr) *details = s;
  if (stats != nullptr) {
    const ShPassTimes w = s.last_wall, g = s.sum_gpu;
    stats->technique = "sh";
    stats->width = scene.camera.width;
    stats->height = scene.camera.height;
    stats->total_ms = now_ms() - t0;
    stats->pass_ms = {{"setup", s.setup_ms},     {"shadow map", w.shadow_ms},
                      {"depth peel", w.peel_ms}, {"depth blur", w.blur_ms},
                      {"cube map", w.cube_ms},   {"projection", w.project_ms},
                      {"final", w.final_ms}};
    stats->details = {{"gl_renderer", s.gl_renderer},
                      {"timing", "one frame after a warm-up frame, glFinish + wall clock"},
                      {"frame_ms", w.total_ms()},
                      {"gpu_query_ms",
                       {{"shadow map", g.shadow_ms},
                        {"depth peel", g.peel_ms},
                        {"depth blur", g.blur_ms},
                        {"cube map", g.cube_ms},
                        {"projection", g.project_ms},
                        {"final", g.final_ms}}},
                      {"primary_light", s.primary_light},
                      {"shadow_texel_mm", s.shadow_texel_mm},
                      {"options", options.to_string()}};
  }
  return image;
}

}  // namespace lucent::render
