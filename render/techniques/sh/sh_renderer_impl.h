// The SH technique's internals (sh_renderer.cpp: building and the passes; sh_renderer_frame.cpp:
// the frame-by-frame API and render_sh): its GL objects, constants and pass timing.
#pragma once

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "gl_api.h"
#include "gl_frame.h"
#include "gl_program.h"
#include "lucent/render/sh_renderer.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {
namespace sh_detail {

inline constexpr int kMaxLights = 16;
inline constexpr float kNoSurface = 1e30f;  // kShNoSurface in sh_light.glsl
inline constexpr int kGroupSize = 256;      // local_size_x of sh_project.comp
// Texture units of the final pass.
inline constexpr GLuint kUnitFirst = 0, kUnitBlurred = 1, kUnitSecond = 2, kUnitEnvironment = 3;

inline double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

enum Pass { kShadow, kPeel, kBlur, kCube, kProject, kFinal, kPassCount };

inline double& pass_field(ShPassTimes& t, int pass) {
  switch (pass) {
    case kShadow:
      return t.shadow_ms;
    case kPeel:
      return t.peel_ms;
    case kBlur:
      return t.blur_ms;
    case kCube:
      return t.cube_ms;
    case kProject:
      return t.project_ms;
    default:
      return t.final_ms;
  }
}

inline ShPassTimes divided(ShPassTimes t, int frames) {
  const double f = std::max(frames, 1);
  for (int p = 0; p < kPassCount; ++p) pass_field(t, p) /= f;
  return t;
}

inline std::vector<std::string> shader_defines() {
  return {"LUCENT_MAX_LIGHTS " + std::to_string(kMaxLights)};
}

inline gl::Sampler make_sampler(GLint filter) {
  gl::Sampler s = gl::create_sampler();
  glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, filter);
  glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, filter);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return s;
}

// The two-stage reduction of sh_project.comp: its program and buffers for one face size.
struct Projector {
  gl::Program program;
  gl::Buffer partials, coefficients;
  int face_size = 0, groups = 0;

  explicit Projector(int w) : face_size(w) {
    program = gl::Program({{GL_COMPUTE_SHADER, "sh_project.comp"}}, shader_defines());
    groups = (6 * w * w + kGroupSize - 1) / kGroupSize;
    partials = gl::create_buffer();
    glNamedBufferStorage(partials.id(), GLsizeiptr(groups) * 27 * GLsizeiptr(sizeof(float)),
                         nullptr, 0);
    coefficients = gl::create_buffer();
    glNamedBufferStorage(coefficients.id(), 27 * sizeof(float), nullptr, GL_DYNAMIC_STORAGE_BIT);
  }

  void run(GLuint cube_texture, GLuint sampler) const;
  std::array<std::array<float, 9>, 3> read() const;
};

}  // namespace sh_detail

using namespace sh_detail;

struct ShRenderer::Impl {
  Scene scene;
  ShOptions options;
  ShOutput output = ShOutput::kImage;
  Vec3f box_min{0, 0, 0}, box_max{0, 0, 0}, centre{0, 0, 0};
  float radius_mm = 1;
  int width = 0, height = 0;

  gl::MeshBuffers mesh;
  gl::VertexArray empty_vao;
  gl::Program depth_program, blur_program, cube_program, final_program;
  std::unique_ptr<Projector> projector;

  gl::Texture first, second, blur_temp, blurred;
  gl::Renderbuffer shadow_depth;
  gl::Framebuffer first_fbo, second_fbo, blur_temp_fbo, blurred_fbo;
  gl::Texture cube;
  gl::Renderbuffer cube_depth;
  std::array<gl::Framebuffer, 6> cube_fbos;
  gl::FinalTarget final;  // the image, its environment, background and present pass
  gl::Sampler nearest;
  std::array<gl::Query, kPassCount> queries;

  detail::LayerCamera light_camera;
  ShStats stats;

  void build(const Scene& s, const ShOptions& o);
  void upload_mesh();
  void build_programs();
  void build_targets();
  void fit_bounds();
  void upload_lights();
  void upload_material();
  void shadow_pass(bool peel);
  void blur_pass();
  void cube_pass();
  void final_pass();
  template <typename F>
  void timed(int pass, F&& work) {
    if (options.time_passes) glFinish();
    const double t0 = now_ms();
    glBeginQuery(GL_TIME_ELAPSED, queries[std::size_t(pass)].id());
    work();
    glEndQuery(GL_TIME_ELAPSED);
    if (options.time_passes) glFinish();
    const double wall = now_ms() - t0;
    GLuint64 ns = 0;
    glGetQueryObjectui64v(queries[std::size_t(pass)].id(), GL_QUERY_RESULT, &ns);
    pass_field(stats.last_wall, pass) = wall;
    pass_field(stats.sum_wall, pass) += wall;
    pass_field(stats.sum_gpu, pass) += double(ns) * 1e-6;
  }
};

}  // namespace lucent::render
