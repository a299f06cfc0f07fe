// The SH fast translucency technique of Banterle & Chalmers on OpenGL 4.5
// (render/include/lucent/render/sh_renderer.h; the passes' math in the sh_*.glsl shaders): the
// options, building the GL objects and the passes. sh_renderer_frame.cpp has the frame API.
#include "sh_renderer_impl.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "area_light.h"
#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/medium.h"
#include "sh_translucency.h"

namespace lucent::render {
namespace {

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
    throw Error("--sh-shadow-map: the shadow map must be 16..8192 texels, got " +
                std::to_string(shadow_map_size));
  }
  if (cube_map_size < 4 || cube_map_size > 2048) {
    throw Error("--sh-cube-map: the cube-map faces must be 4..2048 texels, got " +
                std::to_string(cube_map_size));
  }
  if (!(depth_blur_sigma_texels >= 0 && depth_blur_sigma_texels <= 32)) {
    throw Error("--sh-depth-blur: sigma must be 0..32 shadow-map texels");
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

void Projector::run(GLuint cube_texture, GLuint sampler) const {
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

std::array<std::array<float, 9>, 3> Projector::read() const {
  std::array<float, 27> flat{};
  glGetNamedBufferSubData(coefficients.id(), 0, 27 * sizeof(float), flat.data());
  std::array<std::array<float, 9>, 3> out{};
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 9; ++k) out[std::size_t(c)][std::size_t(k)] = flat[std::size_t(9 * c + k)];
  }
  return out;
}

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
  mesh = gl::upload_mesh(scene.mesh);
  empty_vao = gl::create_vertex_array();
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
  nearest = make_sampler(GL_NEAREST);
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

  final.build(scene, width, height, kUnitEnvironment);
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
  // Area lights enter as point lights at their centroids (point_light_equivalent): the technique's
  // cube map and thickness look-up follow one position per light.
  std::vector<Light> lights;
  for (const Light& light : scene.lights) lights.push_back(point_light_equivalent(light));
  for (int l = 0; l < L; ++l) {
    const Light& light = lights[std::size_t(l)];
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
  const Light& p = lights[std::size_t(primary)];
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
  mesh.draw();
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
  const float zero[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  for (int f = 0; f < 6; ++f) {
    const GLuint fbo = cube_fbos[std::size_t(f)].id();
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
    const detail::Mat4f m = face_matrix(f);
    glUniformMatrix4fv(cube_program.location("u_face"), 1, GL_FALSE, m.data());
    mesh.draw();
  }
}

void ShRenderer::Impl::final_pass() {
  const detail::Mat4f view_proj = detail::camera_view_proj(scene.camera, centre, radius_mm);
  final.begin_frame(view_proj, scene.backdrop);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  final_program.use();
  glUniformMatrix4fv(final_program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(final_program.location("u_eye"), 1, scene.camera.eye.data());
  glUniform1f(final_program.location("u_roughness"), scene.roughness);
  glUniform1i(final_program.location("u_specular"), scene.specular ? 1 : 0);
  glUniform1i(final_program.location("u_has_environment"), final.has_environment() ? 1 : 0);
  glUniform1i(final_program.location("u_output"), int(output));
  glBindTextureUnit(kUnitFirst, first.id());
  glBindSampler(kUnitFirst, nearest.id());
  glBindTextureUnit(kUnitBlurred, blurred.id());
  glBindSampler(kUnitBlurred, nearest.id());
  glBindTextureUnit(kUnitSecond, second.id());
  glBindSampler(kUnitSecond, nearest.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, projector->coefficients.id());
  mesh.draw();
}

}  // namespace lucent::render
