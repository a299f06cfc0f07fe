// `--technique fur` on OpenGL 4.5 (render/include/lucent/render/fur_renderer.h).
#include "lucent/render/fur_renderer.h"

#include <chrono>
#include <cmath>

#include "area_light.h"
#include "fur_gl.h"
#include "gl_api.h"
#include "gl_frame.h"
#include "gl_program.h"
#include "lucent/core/error.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/technique.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {

namespace detail {

gl::Texture upload_fur_transfer(const fur::FurTile& tile) {
  // 7 RGBA layers per shell: t_0..t_23, then t_24 and the coverage.
  const int n = tile.texels, S = tile.shells;
  std::vector<float> layers(std::size_t(n) * n * 4 * 7 * S, 0.0f);
  for (int s = 0; s < S; ++s) {
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const float* t = &tile.transfer[((std::size_t(s) * n + y) * n + x) * kShCoefficients];
        for (int k = 0; k < 7; ++k) {
          float* out = &layers[((std::size_t(7 * s + k) * n + y) * n + x) * 4];
          for (int c = 0; c < 4; ++c) {
            const int i = 4 * k + c;
            out[c] = i < kShCoefficients ? t[i] : 0.0f;
          }
          if (k == 6) out[1] = tile.at(s, y, x);
        }
      }
    }
  }
  GLint max_layers = 0, max_size = 0;
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (7 * S > max_layers || n > max_size) {
    throw Error("--fur-shells, --fur-texels: " + std::to_string(S) + " shells need " +
                std::to_string(7 * S) + " texture layers of " + std::to_string(n) + "^2 texels; " +
                "this OpenGL allows " + std::to_string(max_layers) + " layers of at most " +
                std::to_string(max_size) + "^2 (at most " + std::to_string(max_layers / 7) +
                " shells)");
  }
  gl::Texture transfer = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(transfer.id(), 1, GL_RGBA32F, n, n, 7 * S);
  glTextureSubImage3D(transfer.id(), 0, 0, 0, 0, n, n, 7 * S, GL_RGBA, GL_FLOAT, layers.data());
  return transfer;
}

gl::Sampler fur_sampler() {
  gl::Sampler sampler = gl::create_sampler();
  glSamplerParameteri(sampler.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(sampler.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(sampler.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glSamplerParameteri(sampler.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return sampler;
}

Vec3f fur_albedo(const materials::Material& material) {
  Vec3f albedo;
  for (int c = 0; c < 3; ++c) {
    const auto md = material.medium(c);
    const double s_prime = md.sigma_s * (1 - md.g);
    albedo[c] = s_prime + md.sigma_a > 0 ? float(s_prime / (s_prime + md.sigma_a)) : 0.0f;
  }
  return albedo;
}

}  // namespace detail

namespace {

double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

}  // namespace

Eigen::Vector3d tile_from_world(const Eigen::Vector3d& w) { return {w.x(), -w.z(), w.y()}; }

Eigen::Matrix3d fur_vertex_frame(const Vec3f& normal) {
  const Eigen::Vector3d n = normal.cast<double>().normalized();
  Eigen::Vector3d t = n.cross(Eigen::Vector3d::UnitY());
  if (t.norm() < 1e-4) t = Eigen::Vector3d::UnitX() - n.x() * n;
  t.normalize();
  Eigen::Matrix3d frame;
  frame.row(0) = t.transpose();
  frame.row(1) = n.cross(t).transpose();
  frame.row(2) = n.transpose();
  return frame;
}

std::array<ShVector<double>, 3> fur_light_sh(const std::vector<Light>& lights, const Vec3f& centre) {
  Eigen::Matrix3d tile;
  tile << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // tile_from_world
  return fur_light_sh(lights, centre, tile);
}

std::array<ShVector<double>, 3> fur_light_sh(const std::vector<Light>& lights, const Vec3f& centre,
                                             const Eigen::Matrix3d& to_local) {
  std::array<ShVector<double>, 3> c{};
  const auto add = [&](const Eigen::Vector3d& world_dir, const Eigen::Vector3d& rgb) {
    const ShVector<double> y = sh_basis<double>(Eigen::Vector3d(to_local * world_dir.normalized()));
    for (int ch = 0; ch < 3; ++ch)
      for (int i = 0; i < kShCoefficients; ++i) c[std::size_t(ch)][std::size_t(i)] += rgb[ch] * y[std::size_t(i)];
  };
  for (const Light& light : lights) {
    const Eigen::Vector3d L = light.radiance.cast<double>();
    if (light.type == LightType::kDirectional) {
      add(light.direction.cast<double>(), L);
    } else if (light.type == LightType::kPoint) {
      const Eigen::Vector3d d = (light.position - centre).cast<double>();
      if (d.norm() > 0) add(d, L / d.squaredNorm());
    } else {
      const double area = area_light_area(light);
      const Eigen::Vector3d n = area_light_normal(light).cast<double>();
      const int side = 8;
      for (int i = 0; i < side; ++i) {
        for (int j = 0; j < side; ++j) {
          const Eigen::Vector3d p =
              area_light_point(light, (i + 0.5) / side, (j + 0.5) / side).cast<double>();
          const Eigen::Vector3d d = p - centre.cast<double>();
          const double r2 = d.squaredNorm();
          const double cos_p = -n.dot(d) / std::sqrt(r2);
          if (r2 > 0 && cos_p > 0) add(d, L * (cos_p * area / (side * side) / r2));
        }
      }
    }
  }
  return c;
}

struct FurRenderer::Impl {
  Scene scene;
  fur::FurOptions options;
  fur::FurTile tile;
  int width = 0, height = 0;
  float half_mm = 50, spacing_mm = 1, radius = 1;
  Vec3f centre = Vec3f::Zero();
  gl::VertexArray vao;
  gl::Program program;
  gl::Texture transfer;
  gl::Sampler sampler;
  // The image, its background and present pass (the tile is shown without an environment).
  gl::FinalTarget final;
  double precompute_ms = 0, draw_ms = 0;
  int frames = 0;  // since setup

  void upload_lights() { upload_sh(fur_light_sh(scene.lights, Vec3f(0, 0, 0))); }
  void upload_sh(const std::array<ShVector<double>, 3>& c) {
    const char* names[3] = {"u_light_r", "u_light_g", "u_light_b"};
    for (int ch = 0; ch < 3; ++ch) {
      float packed[28] = {};
      for (int i = 0; i < kShCoefficients; ++i) packed[i] = float(c[std::size_t(ch)][std::size_t(i)]);
      glProgramUniform4fv(program.id(), program.location(names[ch]), 7, packed);
    }
  }
};

FurRenderer::FurRenderer() : impl_(std::make_unique<Impl>()) {}
FurRenderer::~FurRenderer() = default;

void FurRenderer::setup(const Scene& scene, const fur::FurOptions& options) {
  Impl& m = *impl_;
  if (scene.mesh.name != "tile") {
    throw Error(
        "--technique fur: the interactive fur is Klotzli & Olano's flat tile (--mesh tile); fur "
        "over a mesh renders with lucent render --technique fur");
  }
  if (scene.lights.empty()) throw Error("--light: the fur technique needs at least one light");
  m.scene = scene;
  m.options = options;
  m.width = scene.camera.width;
  m.height = scene.camera.height;
  const Vec3f lo = scene.mesh.bounds_min(), hi = scene.mesh.bounds_max();
  m.half_mm = 0.5f * (hi.x() - lo.x());
  // The mesh's height holds the shells: their spacing in texels follows from it.
  m.options.shell_spacing = double(hi.y() - lo.y()) / (2.0 * m.half_mm) * m.options.texels / m.options.shells;
  m.spacing_mm = float(hi.y() - lo.y()) / float(m.options.shells);
  m.centre = scene.mesh.centre();
  m.radius = scene.mesh.bounding_radius();
  const double t0 = now_ms();
  m.tile = fur::make_fur_tile(m.options);
  m.precompute_ms = now_ms() - t0;

  m.transfer = detail::upload_fur_transfer(m.tile);
  m.sampler = detail::fur_sampler();
  m.vao = gl::create_vertex_array();
  m.program = gl::Program({{GL_VERTEX_SHADER, "fur.vert"}, {GL_FRAGMENT_SHADER, "fur.frag"}});
  glProgramUniform1i(m.program.id(), m.program.location("u_transfer"), 0);
  m.final.build(scene, m.width, m.height, 1, false);
  const Vec3f albedo = detail::fur_albedo(scene.material);
  glProgramUniform3fv(m.program.id(), m.program.location("u_albedo"), 1, albedo.data());
  m.upload_lights();
  gl::check_errors("fur setup");
}

void FurRenderer::set_camera(const Camera& camera) {
  if (camera.width != impl_->width || camera.height != impl_->height) {
    throw Error("fur: the camera's size cannot change after setup");
  }
  impl_->scene.camera = camera;
}

void FurRenderer::set_lights(const std::vector<Light>& lights) {
  impl_->scene.lights = lights;
  impl_->upload_lights();
}

void FurRenderer::set_material(const materials::Material& material) {
  Impl& m = *impl_;
  m.scene.material = material;
  const Vec3f albedo = detail::fur_albedo(material);
  glProgramUniform3fv(m.program.id(), m.program.location("u_albedo"), 1, albedo.data());
}

void FurRenderer::setup(const Scene& scene, const TechniqueOptions& options) {
  setup(scene, options.fur);
}

bool FurRenderer::converged() const {
  return impl_->frames > 0;
}

FrameStats FurRenderer::frame_stats() const {
  FrameStats f;
  f.frames = impl_->frames;
  f.pass_ms = {{"precompute", impl_->precompute_ms}, {"draw", impl_->draw_ms}};
  f.notes.push_back(std::to_string(impl_->options.shells) + " shells");
  return f;
}

std::vector<std::uint8_t> FurRenderer::read_mask() const {
  return impl_->final.read_mask();
}

void FurRenderer::set_light_sh(const std::array<ShVector<double>, 3>& light) {
  impl_->upload_sh(light);
}

void FurRenderer::present(float exposure, int x, int y, int width, int height) const {
  impl_->final.present(exposure, x, y, width, height);
}

bool FurRenderer::render_frame() {
  Impl& m = *impl_;
  const double t0 = now_ms();
  const detail::Mat4f view_proj = detail::camera_view_proj(m.scene.camera, m.centre, m.radius);
  m.final.begin_frame(view_proj, m.scene.backdrop);
  m.program.use();
  glBindVertexArray(m.vao.id());
  glBindTextureUnit(0, m.transfer.id());
  glBindSampler(0, m.sampler.id());
  glUniformMatrix4fv(m.program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform1f(m.program.location("u_half_mm"), m.half_mm);
  glUniform1f(m.program.location("u_spacing_mm"), m.spacing_mm);
  glUniform1i(m.program.location("u_shells"), m.options.shells);
  // Back to front: from the skin up when the eye is above the top shell.
  const float top = float(m.options.shells) * m.spacing_mm;
  glUniform1i(m.program.location("u_reverse"), m.scene.camera.eye.y() < top ? 1 : 0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glUniform1i(m.program.location("u_skin"), 1);
  glDrawArraysInstanced(GL_TRIANGLES, 0, 6, 1);
  glUniform1i(m.program.location("u_skin"), 0);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glDrawArraysInstanced(GL_TRIANGLES, 0, 6, m.options.shells);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glFinish();
  m.draw_ms = now_ms() - t0;
  ++m.frames;
  gl::check_errors("a fur frame");
  return true;
}

ImageRgb FurRenderer::read_image() const {
  return impl_->final.read_image();
}

double FurRenderer::precompute_ms() const { return impl_->precompute_ms; }
double FurRenderer::draw_ms() const { return impl_->draw_ms; }

ImageRgb render_fur(const Scene& scene, const fur::FurOptions& options, RenderStats* stats,
                    const RenderSettings& skin, const SkinRenderer& skin_renderer) {
  if (scene.mesh.name != "tile") return render_fur_mesh(scene, options, skin, stats, skin_renderer);
  const double t0 = now_ms();
  const auto context = GlContext::create_headless();
  FurRenderer renderer;
  renderer.setup(scene, options);
  renderer.render_frame();  // the first frame compiles shaders on llvmpipe
  renderer.render_frame();
  ImageRgb image = renderer.read_image();
  if (stats != nullptr) {
    stats->technique = "fur";
    stats->width = scene.camera.width;
    stats->height = scene.camera.height;
    stats->total_ms = now_ms() - t0;
    stats->pass_ms = {{"precompute", renderer.precompute_ms()}, {"draw", renderer.draw_ms()}};
    stats->details = {{"texels", options.texels},
                      {"shells", options.shells},
                      {"hairs", options.overcoat.hairs + options.undercoat.hairs},
                      {"timing", "draw: the second frame, glFinish and wall clock"}};
  }
  return image;
}

}  // namespace lucent::render
