// The SH fast translucency technique of seed 000 on OpenGL 4.5
// (render/include/lucent/render/sh_renderer.h; the passes' math in the sh_*.glsl shaders).
#include "lucent/render/sh_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "gl_api.h"
#include "gl_program.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/error.h"
#include "lucent/materials/medium.h"
#include "lucent/render/environment.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/sh_translucency.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {
namespace {

constexpr int kMaxLights = 16;
constexpr float kNoSurface = 1e30f;  // kShNoSurface in sh_light.glsl
constexpr int kGroupSize = 256;      // local_size_x of sh_project.comp
// Texture units of the final pass.
constexpr GLuint kUnitFirst = 0, kUnitBlurred = 1, kUnitSecond = 2, kUnitEnvironment = 3;

double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

enum Pass { kShadow, kPeel, kBlur, kCube, kProject, kFinal, kPassCount };

double& pass_field(ShPassTimes& t, int pass) {
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

ShPassTimes divided(ShPassTimes t, int frames) {
  const double f = std::max(frames, 1);
  for (int p = 0; p < kPassCount; ++p) pass_field(t, p) /= f;
  return t;
}

std::vector<std::string> shader_defines() {
  return {"LUCENT_MAX_LIGHTS " + std::to_string(kMaxLights)};
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

  void run(GLuint cube_texture, GLuint sampler) const {
    program.use();
    glBindTextureUnit(0, cube_texture);
    glBindSampler(0, sampler);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, partials.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, coefficients.id());
    glUniform1i(program.location("u_face_size"), face_size);
    glUniform1i(program.location("u_group_count"), groups);
    glUniform1i(program.location("u_stage"), 0);
    glDispatchCompute(GLuint(groups), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUniform1i(program.location("u_stage"), 1);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }

  std::array<std::array<float, 9>, 3> read() const {
    std::array<float, 27> flat{};
    glGetNamedBufferSubData(coefficients.id(), 0, 27 * sizeof(float), flat.data());
    std::array<std::array<float, 9>, 3> out{};
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 9; ++k) out[std::size_t(c)][std::size_t(k)] = flat[std::size_t(9 * c + k)];
    }
    return out;
  }
};

gl::Sampler make_sampler(GLint filter) {
  gl::Sampler s = gl::create_sampler();
  glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, filter);
  glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, filter);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return s;
}

// Row-major image of the GL matrix taking box coordinates q in [-1, 1]^3 to face f's clip space:
// x = q . U, y = q . V, z = -q . N (nearer the face's side is in front), with U, V, N the face's
// axes from sh::cube_face_point; z shrunk by 0.999 so the box's own faces are not clipped.
detail::Mat4f face_matrix(int f) {
  using sh::CubeFace;
  const auto face = static_cast<CubeFace>(f);
  const Vec3f n = sh::cube_face_point<float>(face, 0.0f, 0.0f);
  const Vec3f u = sh::cube_face_point<float>(face, 1.0f, 0.0f) - n;
  const Vec3f v = sh::cube_face_point<float>(face, 0.0f, 1.0f) - n;
  detail::Mat4f m = detail::Mat4f::Identity();
  m.block<1, 3>(0, 0) = u.transpose();
  m.block<1, 3>(1, 0) = v.transpose();
  m.block<1, 3>(2, 0) = -0.999f * n.transpose();
  return m;
}

float luminance(const Vec3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

}  // namespace

ShAttenuation parse_sh_attenuation(const std::string& text) {
  if (text == "seed") return ShAttenuation::kSeed;
  if (text == "normalised") return ShAttenuation::kNormalised;
  if (text == "slab") return ShAttenuation::kSlab;
  throw Error("--sh-attenuation: expected seed, normalised or slab, got '" + text + "'");
}

std::string to_string(ShAttenuation attenuation) {
  switch (attenuation) {
    case ShAttenuation::kSeed:
      return "seed";
    case ShAttenuation::kNormalised:
      return "normalised";
    case ShAttenuation::kSlab:
      break;
  }
  return "slab";
}

void ShOptions::validate() const {
  if (shadow_map_size < 16 || shadow_map_size > 8192) {
    throw Error("--shadow-map: the shadow map must be 16..8192 texels, got " +
                std::to_string(shadow_map_size));
  }
  if (cube_map_size < 4 || cube_map_size > 2048) {
    throw Error("--cube-map: the cube-map faces must be 4..2048 texels, got " +
                std::to_string(cube_map_size));
  }
  if (!(depth_blur_sigma_texels >= 0 && depth_blur_sigma_texels <= 32)) {
    throw Error("--depth-blur: sigma must be 0..32 shadow-map texels");
  }
  if (!(shadow_bias_texels >= 0 && shadow_bias_texels <= 64)) {
    throw Error("sh: the shadow bias must be 0..64 texels");
  }
}

std::string ShOptions::to_string() const {
  std::ostringstream s;
  s << "ShOptions{shadow_map_size=" << shadow_map_size << ", cube_map_size=" << cube_map_size
    << ", depth_blur_sigma_texels=" << depth_blur_sigma_texels
    << ", shadow_bias_texels=" << shadow_bias_texels
    << ", attenuation=" << lucent::render::to_string(attenuation) << ", fresnel=" << (schlick ? "schlick" : "exact")
    << "}";
  return s.str();
}

ShPassTimes ShStats::mean_wall() const {
  return divided(sum_wall, frames);
}
ShPassTimes ShStats::mean_gpu() const {
  return divided(sum_gpu, frames);
}

struct ShRenderer::Impl {
  Scene scene;
  ShOptions options;
  ShOutput output = ShOutput::kImage;
  Vec3f box_min{0, 0, 0}, box_max{0, 0, 0}, centre{0, 0, 0};
  float radius_mm = 1;
  int width = 0, height = 0;

  gl::VertexArray mesh_vao, empty_vao;
  gl::Buffer positions, normals, indices;
  GLsizei index_count = 0;
  gl::Program depth_program, blur_program, cube_program, final_program, background_program,
      present_program;
  std::unique_ptr<Projector> projector;

  gl::Texture first, second, blur_temp, blurred;
  gl::Renderbuffer shadow_depth;
  gl::Framebuffer first_fbo, second_fbo, blur_temp_fbo, blurred_fbo;
  gl::Texture cube;
  gl::Renderbuffer cube_depth;
  std::array<gl::Framebuffer, 6> cube_fbos;
  gl::Texture final_color;
  gl::Renderbuffer final_depth;
  gl::Framebuffer final_fbo;
  gl::Texture environment;
  bool has_environment = false;
  gl::Sampler nearest, linear, environment_sampler;
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
  std::vector<float> read_rgba() const;
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

void ShRenderer::Impl::build(const Scene& s, const ShOptions& o) {
  scene = s;
  options = o;
  options.validate();
  const Mesh& m = scene.mesh;
  if (m.positions.empty() || m.triangles.empty()) {
    throw Error("sh: the mesh '" + m.name + "' is empty");
  }
  if (m.normals.size() != m.positions.size()) {
    throw Error("sh: the mesh '" + m.name + "' has no per-vertex normals");
  }
  if (scene.lights.empty()) throw Error("--light: the sh technique needs at least one light");
  if (int(scene.lights.size()) > kMaxLights) {
    throw Error("--light: the sh technique takes at most " + std::to_string(kMaxLights) +
                " lights, got " + std::to_string(scene.lights.size()));
  }
  width = scene.camera.width;
  height = scene.camera.height;
  if (width < 1 || height < 1) throw Error("--size: the image has no pixels");
  stats.gl_renderer = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) +
                      " | " + reinterpret_cast<const char*>(glGetString(GL_VERSION));
  upload_mesh();
  build_programs();
  build_targets();
  for (auto& q : queries) q = gl::create_query(GL_TIME_ELAPSED);
  fit_bounds();
  upload_material();
  upload_lights();
  gl::check_errors("sh setup");
}

void ShRenderer::Impl::upload_mesh() {
  const Mesh& m = scene.mesh;
  mesh_vao = gl::create_vertex_array();
  empty_vao = gl::create_vertex_array();
  positions = gl::create_buffer();
  normals = gl::create_buffer();
  indices = gl::create_buffer();
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  glNamedBufferStorage(positions.id(), GLsizeiptr(m.positions.size() * sizeof(Vec3f)),
                       m.positions.data(), GL_DYNAMIC_STORAGE_BIT);
  glNamedBufferStorage(normals.id(), GLsizeiptr(m.normals.size() * sizeof(Vec3f)),
                       m.normals.data(), GL_DYNAMIC_STORAGE_BIT);
  glNamedBufferStorage(indices.id(), GLsizeiptr(m.triangles.size() * sizeof(m.triangles[0])),
                       m.triangles.data(), 0);
  index_count = GLsizei(m.triangles.size() * 3);
  const GLuint vao = mesh_vao.id();
  glVertexArrayVertexBuffer(vao, 0, positions.id(), 0, sizeof(Vec3f));
  glVertexArrayVertexBuffer(vao, 1, normals.id(), 0, sizeof(Vec3f));
  glVertexArrayElementBuffer(vao, indices.id());
  for (GLuint a = 0; a < 2; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, a, a);
  }
}

void ShRenderer::Impl::build_programs() {
  const auto defines = shader_defines();
  depth_program = gl::Program(
      {{GL_VERTEX_SHADER, "sh_depth.vert"}, {GL_FRAGMENT_SHADER, "sh_depth.frag"}}, defines);
  blur_program = gl::Program(
      {{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "sh_blur.frag"}}, defines);
  cube_program = gl::Program(
      {{GL_VERTEX_SHADER, "sh_cube.vert"}, {GL_FRAGMENT_SHADER, "sh_cube.frag"}}, defines);
  final_program = gl::Program(
      {{GL_VERTEX_SHADER, "final.vert"}, {GL_FRAGMENT_SHADER, "sh_final.frag"}}, defines);
  background_program = gl::Program(
      {{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "background.frag"}}, defines);
  present_program = gl::Program(
      {{GL_VERTEX_SHADER, "background.vert"}, {GL_FRAGMENT_SHADER, "present.frag"}}, defines);
  projector = std::make_unique<Projector>(options.cube_map_size);
  const auto unit = [](const gl::Program& p, const char* name, GLint u) {
    glProgramUniform1i(p.id(), p.location(name), u);
  };
  unit(depth_program, "u_first_depth", 0);
  unit(blur_program, "u_source", 0);
  unit(cube_program, "u_first_depth", 0);
  unit(final_program, "u_first_depth", kUnitFirst);
  unit(final_program, "u_blurred_depth", kUnitBlurred);
  unit(final_program, "u_second_depth", kUnitSecond);
  unit(final_program, "u_environment", kUnitEnvironment);
  unit(background_program, "u_environment", kUnitEnvironment);
  unit(present_program, "u_image", 0);
  nearest = make_sampler(GL_NEAREST);
  linear = make_sampler(GL_LINEAR);
  environment_sampler = make_sampler(GL_LINEAR);
  glSamplerParameteri(environment_sampler.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
}

void ShRenderer::Impl::build_targets() {
  const int S = options.shadow_map_size;
  const auto depth_target = [&](gl::Texture& tex, gl::Framebuffer& fbo, bool with_depth) {
    tex = gl::create_texture(GL_TEXTURE_2D);
    glTextureStorage2D(tex.id(), 1, GL_R32F, S, S);
    fbo = gl::create_framebuffer();
    glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0, tex.id(), 0);
    if (with_depth) {
      glNamedFramebufferRenderbuffer(fbo.id(), GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                     shadow_depth.id());
    }
    gl::check_framebuffer(fbo.id(), "the sh shadow map");
  };
  shadow_depth = gl::create_renderbuffer();
  glNamedRenderbufferStorage(shadow_depth.id(), GL_DEPTH_COMPONENT32F, S, S);
  depth_target(first, first_fbo, true);
  depth_target(second, second_fbo, true);
  depth_target(blur_temp, blur_temp_fbo, false);
  depth_target(blurred, blurred_fbo, false);

  const int W = options.cube_map_size;
  cube = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(cube.id(), 1, GL_RGBA32F, W, W, 6);
  cube_depth = gl::create_renderbuffer();
  glNamedRenderbufferStorage(cube_depth.id(), GL_DEPTH_COMPONENT32F, W, W);
  for (int f = 0; f < 6; ++f) {
    cube_fbos[std::size_t(f)] = gl::create_framebuffer();
    const GLuint fbo = cube_fbos[std::size_t(f)].id();
    glNamedFramebufferTextureLayer(fbo, GL_COLOR_ATTACHMENT0, cube.id(), 0, f);
    glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, cube_depth.id());
    gl::check_framebuffer(fbo, "the sh cube map");
  }

  final_color = gl::create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(final_color.id(), 1, GL_RGBA32F, width, height);
  final_depth = gl::create_renderbuffer();
  glNamedRenderbufferStorage(final_depth.id(), GL_DEPTH_COMPONENT32F, width, height);
  final_fbo = gl::create_framebuffer();
  glNamedFramebufferTexture(final_fbo.id(), GL_COLOR_ATTACHMENT0, final_color.id(), 0);
  glNamedFramebufferRenderbuffer(final_fbo.id(), GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                 final_depth.id());
  gl::check_framebuffer(final_fbo.id(), "the final image");

  has_environment = false;
  if (scene.environment) {
    const EnvironmentMap map = load_environment(*scene.environment);
    environment = gl::create_texture(GL_TEXTURE_2D);
    glTextureStorage2D(environment.id(), 1, GL_RGB32F, map.image.width, map.image.height);
    glTextureSubImage2D(environment.id(), 0, 0, 0, map.image.width, map.image.height, GL_RGB,
                        GL_FLOAT, map.image.data.data());
    has_environment = true;
  }
}

void ShRenderer::Impl::fit_bounds() {
  const Mesh& m = scene.mesh;
  box_min = m.bounds_min();
  box_max = m.bounds_max();
  // A flat mesh has a box of zero thickness: pad every axis by 0.5% of the diagonal so that the
  // box-to-cube scale stays finite and the surfaces lie strictly inside the face cameras' range.
  const float pad = 0.005f * std::max((box_max - box_min).norm(), 1e-6f);
  box_min.array() -= pad;
  box_max.array() += pad;
  centre = m.centre();
  radius_mm = m.bounding_radius();
  const Vec3f half = (box_max - box_min) / 2;
  const Vec3f mid = (box_max + box_min) / 2;
  glProgramUniform3fv(cube_program.id(), cube_program.location("u_box_centre"), 1, mid.data());
  glProgramUniform3fv(cube_program.id(), cube_program.location("u_box_half"), 1, half.data());
  glProgramUniform3fv(final_program.id(), final_program.location("u_box_min"), 1, box_min.data());
  glProgramUniform3fv(final_program.id(), final_program.location("u_box_max"), 1, box_max.data());
}

void ShRenderer::Impl::upload_lights() {
  const int L = int(scene.lights.size());
  std::vector<float> position(std::size_t(kMaxLights) * 4, 0.0f);
  std::vector<float> radiance(std::size_t(kMaxLights) * 3, 0.0f);
  int primary = 0;
  float brightest = -1;
  for (int l = 0; l < L; ++l) {
    const Light& light = scene.lights[std::size_t(l)];
    float* p = &position[std::size_t(l) * 4];
    float e = luminance(light.radiance);
    if (light.type == LightType::kDirectional) {
      const Vec3f d = light.direction.normalized();
      p[0] = d.x(), p[1] = d.y(), p[2] = d.z(), p[3] = 0;
    } else {
      p[0] = light.position.x(), p[1] = light.position.y(), p[2] = light.position.z(), p[3] = 1;
      e /= std::max((light.position - centre).squaredNorm(), 1e-12f);
    }
    for (int c = 0; c < 3; ++c) radiance[std::size_t(l) * 3 + std::size_t(c)] = light.radiance[c];
    if (e > brightest) brightest = e, primary = l;
  }
  const Light& p = scene.lights[std::size_t(primary)];
  const float S = float(options.shadow_map_size);
  if (p.type == LightType::kDirectional) {
    light_camera = detail::fitted_orthographic(centre, radius_mm, p.direction.normalized());
    stats.shadow_texel_mm = light_camera.extent_mm / S;
  } else {
    light_camera = detail::fitted_perspective(centre, radius_mm, p.position);
    stats.shadow_texel_mm = light_camera.extent_per_mm * (p.position - centre).norm() / S;
  }
  stats.primary_light = primary;
  const float bias = options.shadow_bias_texels * float(stats.shadow_texel_mm);
  for (const gl::Program* prog : {&depth_program, &cube_program, &final_program}) {
    const GLuint id = prog->id();
    glProgramUniform1i(id, prog->location("u_light_count"), L);
    glProgramUniform4fv(id, prog->location("u_light_position"), kMaxLights, position.data());
    glProgramUniform3fv(id, prog->location("u_light_radiance"), kMaxLights, radiance.data());
    glProgramUniform1i(id, prog->location("u_primary"), primary);
    glProgramUniformMatrix4fv(id, prog->location("u_primary_view_proj"), 1, GL_FALSE,
                              light_camera.view_proj.data());
    glProgramUniform1f(id, prog->location("u_shadow_bias_mm"), bias);
  }
}

void ShRenderer::Impl::upload_material() {
  Vec3f sigma_tr, sigma_t_reduced, scale(1, 1, 1);
  for (int c = 0; c < 3; ++c) {
    const auto k = materials::derive_coefficients(scene.material.medium(c));
    sigma_tr[c] = float(k.sigma_tr);
    sigma_t_reduced[c] = float(k.sigma_t_reduced);
    if (options.attenuation != ShAttenuation::kSeed) {
      const double a0 = options.attenuation == ShAttenuation::kSlab
                            ? sh::attenuation_slab<double>(0.0, k.sigma_tr, k.sigma_t_reduced)
                            : sh::attenuation<double>(0.0, k.sigma_tr, k.sigma_t_reduced);
      scale[c] = a0 > 0 ? float(materials::dipole_total_reflectance(k.alpha_prime, k.A_dipole) / a0)
                        : 0.0f;
    }
  }
  glProgramUniform3fv(final_program.id(), final_program.location("u_attenuation_scale"), 1,
                      scale.data());
  glProgramUniform1i(final_program.id(), final_program.location("u_slab"),
                     options.attenuation == ShAttenuation::kSlab ? 1 : 0);
  const float eta = float(scene.material.ior);
  const GLuint f = final_program.id();
  glProgramUniform3fv(f, final_program.location("u_sigma_tr"), 1, sigma_tr.data());
  glProgramUniform3fv(f, final_program.location("u_sigma_t_reduced"), 1, sigma_t_reduced.data());
  glProgramUniform1f(f, final_program.location("u_eta"), eta);
  glProgramUniform1f(cube_program.id(), cube_program.location("u_eta"), eta);
  glProgramUniform1i(cube_program.id(), cube_program.location("u_schlick"), options.schlick);
}

void ShRenderer::Impl::shadow_pass(bool peel) {
  const int S = options.shadow_map_size;
  const gl::Framebuffer& fbo = peel ? second_fbo : first_fbo;
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, S, S);
  const float empty[4] = {kNoSurface, 0, 0, 0};
  const float one = 1.0f;
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, empty);
  glClearNamedFramebufferfv(fbo.id(), GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  depth_program.use();
  glUniform1i(depth_program.location("u_peel"), peel ? 1 : 0);
  glBindTextureUnit(0, first.id());
  glBindSampler(0, nearest.id());
  glBindVertexArray(mesh_vao.id());
  glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
}

void ShRenderer::Impl::blur_pass() {
  const int S = options.shadow_map_size;
  glDisable(GL_DEPTH_TEST);
  glViewport(0, 0, S, S);
  blur_program.use();
  glUniform1f(blur_program.location("u_sigma_texels"), options.depth_blur_sigma_texels);
  glBindVertexArray(empty_vao.id());
  glBindSampler(0, nearest.id());
  const struct {
    const gl::Texture& source;
    const gl::Framebuffer& target;
    int dx, dy;
  } steps[] = {{first, blur_temp_fbo, 1, 0}, {blur_temp, blurred_fbo, 0, 1}};
  for (const auto& step : steps) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, step.target.id());
    glBindTextureUnit(0, step.source.id());
    glUniform2i(blur_program.location("u_step"), step.dx, step.dy);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
}

void ShRenderer::Impl::cube_pass() {
  const int W = options.cube_map_size;
  glViewport(0, 0, W, W);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  cube_program.use();
  glBindTextureUnit(0, first.id());
  glBindSampler(0, nearest.id());
  glBindVertexArray(mesh_vao.id());
  const float zero[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  for (int f = 0; f < 6; ++f) {
    const GLuint fbo = cube_fbos[std::size_t(f)].id();
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
    const detail::Mat4f m = face_matrix(f);
    glUniformMatrix4fv(cube_program.location("u_face"), 1, GL_FALSE, m.data());
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
  }
}

void ShRenderer::Impl::final_pass() {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, final_fbo.id());
  glViewport(0, 0, width, height);
  const float one = 1.0f;
  glClearNamedFramebufferfv(final_fbo.id(), GL_DEPTH, 0, &one);
  const detail::Mat4f view_proj = detail::camera_view_proj(scene.camera, centre, radius_mm);
  glDisable(GL_DEPTH_TEST);
  background_program.use();
  const detail::Mat4f inverse = view_proj.inverse();
  glUniformMatrix4fv(background_program.location("u_inverse_view_proj"), 1, GL_FALSE,
                     inverse.data());
  glUniform1i(background_program.location("u_has_environment"), has_environment ? 1 : 0);
  glUniform3fv(background_program.location("u_backdrop"), 1, scene.backdrop.data());
  if (has_environment) {
    glBindTextureUnit(kUnitEnvironment, environment.id());
    glBindSampler(kUnitEnvironment, environment_sampler.id());
  }
  glBindVertexArray(empty_vao.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  final_program.use();
  glUniformMatrix4fv(final_program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(final_program.location("u_eye"), 1, scene.camera.eye.data());
  glUniform1f(final_program.location("u_roughness"), scene.roughness);
  glUniform1i(final_program.location("u_specular"), scene.specular ? 1 : 0);
  glUniform1i(final_program.location("u_has_environment"), has_environment ? 1 : 0);
  glUniform1i(final_program.location("u_output"), int(output));
  glBindTextureUnit(kUnitFirst, first.id());
  glBindSampler(kUnitFirst, nearest.id());
  glBindTextureUnit(kUnitBlurred, blurred.id());
  glBindSampler(kUnitBlurred, nearest.id());
  glBindTextureUnit(kUnitSecond, second.id());
  glBindSampler(kUnitSecond, nearest.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, projector->coefficients.id());
  glBindVertexArray(mesh_vao.id());
  glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
}

std::vector<float> ShRenderer::Impl::read_rgba() const {
  std::vector<float> rgba(std::size_t(width) * std::size_t(height) * 4);
  glGetTextureImage(final_color.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)),
                    rgba.data());
  return rgba;
}

ShRenderer::ShRenderer() : impl_(std::make_unique<Impl>()) {}
ShRenderer::~ShRenderer() = default;

void ShRenderer::setup(const Scene& scene, const ShOptions& options) {
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
  if (positions.size() != m.scene.mesh.positions.size() || normals.size() != positions.size()) {
    throw Error("sh: set_geometry needs " + std::to_string(m.scene.mesh.positions.size()) +
                " positions and normals");
  }
  m.scene.mesh.positions = positions;
  m.scene.mesh.normals = normals;
  glNamedBufferSubData(m.positions.id(), 0, GLsizeiptr(positions.size() * sizeof(Vec3f)),
                       positions.data());
  glNamedBufferSubData(m.normals.id(), 0, GLsizeiptr(normals.size() * sizeof(Vec3f)),
                       normals.data());
  m.fit_bounds();
  m.upload_lights();  // the shadow camera is fitted to the new bounds
}

void ShRenderer::set_output(ShOutput output) {
  impl_->output = output;
}

void ShRenderer::render_frame() {
  Impl& m = *impl_;
  m.timed(kShadow, [&] { m.shadow_pass(false); });
  m.timed(kPeel, [&] { m.shadow_pass(true); });
  m.timed(kBlur, [&] { m.blur_pass(); });
  m.timed(kCube, [&] { m.cube_pass(); });
  m.timed(kProject, [&] { m.projector->run(m.cube.id(), m.nearest.id()); });
  m.timed(kFinal, [&] { m.final_pass(); });
  ++m.stats.frames;
  gl::check_errors("an sh frame");
}

ImageRgb ShRenderer::read_image() const {
  const Impl& m = *impl_;
  const std::vector<float> rgba = m.read_rgba();
  ImageRgb image(m.width, m.height);
  for (int y = 0; y < m.height; ++y) {
    const int row = m.height - 1 - y;  // GL rows go up from the bottom
    for (int x = 0; x < m.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) = rgba[(std::size_t(row) * std::size_t(m.width) + std::size_t(x)) * 4 +
                                 std::size_t(c)];
      }
    }
  }
  return image;
}

std::vector<std::uint8_t> ShRenderer::read_mask() const {
  const Impl& m = *impl_;
  const std::vector<float> rgba = m.read_rgba();
  std::vector<std::uint8_t> mask(std::size_t(m.width) * std::size_t(m.height));
  for (int y = 0; y < m.height; ++y) {
    const int row = m.height - 1 - y;
    for (int x = 0; x < m.width; ++x) {
      mask[std::size_t(y) * std::size_t(m.width) + std::size_t(x)] =
          rgba[(std::size_t(row) * std::size_t(m.width) + std::size_t(x)) * 4 + 3] > 0 ? 1 : 0;
    }
  }
  return mask;
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

void ShRenderer::present(float exposure, int width, int height) const {
  const Impl& m = *impl_;
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  m.present_program.use();
  glUniform1f(m.present_program.location("u_exposure"), exposure);
  glBindTextureUnit(0, m.final_color.id());
  glBindSampler(0, m.linear.id());
  glBindVertexArray(m.empty_vao.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
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
