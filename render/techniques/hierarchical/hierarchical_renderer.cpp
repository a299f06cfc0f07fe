// The hierarchical technique's GL side (hierarchical_renderer.h): the mesh with a third vertex
// stream for B, the shading pass, read-back and present.
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/technique.h"

#include <chrono>
#include <thread>

#include "gl_api.h"
#include "gl_area_lights.h"
#include "gl_bssrdf.h"
#include "gl_frame.h"
#include "gl_program.h"
#include "hierarchical_single.h"
#include "lucent/core/error.h"
#include "lucent/render/gl_context.h"
#include "radiance_maps_sampling.h"

namespace lucent::render {
namespace {

constexpr int kMaxLights = 16;
constexpr GLuint kUnitEnvironment = 0;

double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

}  // namespace

struct HierarchicalRenderer::Impl {
  Scene scene;
  std::unique_ptr<hierarchical::Solver> solver;
  gl::MeshBuffers mesh;
  gl::Buffer B;
  gl::Buffer single;  // the single scattering per vertex toward the eye (zeros when off)
  std::unique_ptr<detail::RayScene> rays;  // for the single scattering; made on first use
  bool single_valid = false;               // for single_eye and the scene's lights and material
  Vec3f single_eye = Vec3f::Zero();
  double single_ms = 0;
  gl::Program program;
  gl::FinalTarget final;  // the image, its environment, background and present pass
  int width = 0, height = 0;
  Vec3f centre = Vec3f::Zero();
  float radius = 1;
  double upload_ms = 0, draw_ms = 0;
  int frames = 0;  // since setup
  std::vector<float> B_floats;

  void fit_bounds() {
    centre = scene.mesh.centre();
    radius = std::max(scene.mesh.bounding_radius(), 1e-6f);
  }

  // The single-scattering stream for the camera's eye, recomputed when the eye, lights, material or
  // geometry changed.
  void update_single() {
    if (!scene.single_scattering) return;
    if (single_valid && single_eye == scene.camera.eye) return;
    const double t0 = now_ms();
    if (!rays) rays = std::make_unique<detail::RayScene>(scene.mesh);
    const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
    const std::vector<float> values = hierarchical::vertex_single_scattering(
        *rays, scene.mesh, scene.material, scene.lights, scene.camera.eye, threads);
    glNamedBufferSubData(single.id(), 0, GLsizeiptr(values.size() * sizeof(float)), values.data());
    single_eye = scene.camera.eye;
    single_valid = true;
    single_ms = now_ms() - t0;
  }

  void upload_lights() {
    if (scene.lights.empty() || int(scene.lights.size()) > kMaxLights) {
      throw Error("--light: the hierarchical technique takes 1.." + std::to_string(kMaxLights) +
                  " lights, got " + std::to_string(scene.lights.size()));
    }
    std::vector<float> position(std::size_t(kMaxLights) * 4, 0.0f), radiance(std::size_t(kMaxLights) * 3, 0.0f);
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const Light& light = scene.lights[l];
      const Vec3f p = light.type == LightType::kDirectional ? Vec3f(light.direction.normalized())
                                                            : light.position;
      for (int k = 0; k < 3; ++k) {
        position[4 * l + std::size_t(k)] = p[k];
        radiance[3 * l + std::size_t(k)] = light.radiance[k];
      }
      position[4 * l + 3] = light.type == LightType::kPoint  ? 1.0f
                            : light.type == LightType::kArea ? float(2 + gl::area_slot(scene.lights, l))
                                                             : 0.0f;
    }
    const GLuint id = program.id();
    gl::upload_area_lights(id, scene.lights);
    gl::set_fur_coat_uniforms(id, scene.fur_coat);  // the specular lobe's light under a coat
    glProgramUniform1i(id, program.location("u_light_count"), GLint(scene.lights.size()));
    glProgramUniform4fv(id, program.location("u_light_position"), kMaxLights, position.data());
    glProgramUniform3fv(id, program.location("u_light_radiance"), kMaxLights, radiance.data());
  }
};

HierarchicalRenderer::HierarchicalRenderer() = default;
HierarchicalRenderer::~HierarchicalRenderer() = default;

void HierarchicalRenderer::setup(const Scene& scene, const hierarchical::Options& options) {
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  m.scene = scene;
  const Mesh& mesh = scene.mesh;
  if (mesh.positions.empty() || mesh.triangles.empty()) {
    throw Error("hierarchical: the mesh '" + mesh.name + "' is empty");
  }
  if (mesh.normals.size() != mesh.positions.size()) {
    throw Error("hierarchical: the mesh '" + mesh.name + "' has no per-vertex normals");
  }
  m.width = scene.camera.width;
  m.height = scene.camera.height;
  if (m.width < 1 || m.height < 1) throw Error("--size: the image has no pixels");
  m.solver = std::make_unique<hierarchical::Solver>(scene, options);
  m.mesh = gl::upload_mesh(mesh);
  m.B = gl::create_buffer();
  glNamedBufferStorage(m.B.id(), GLsizeiptr(mesh.positions.size() * 3 * sizeof(float)), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
  const GLuint vao = m.mesh.vao.id();
  glVertexArrayVertexBuffer(vao, 2, m.B.id(), 0, 3 * sizeof(float));
  glEnableVertexArrayAttrib(vao, 2);
  glVertexArrayAttribFormat(vao, 2, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 2, 2);
  const std::vector<float> zeros(mesh.positions.size() * 3, 0.0f);
  m.single = gl::create_buffer();
  glNamedBufferStorage(m.single.id(), GLsizeiptr(zeros.size() * sizeof(float)), zeros.data(),
                       GL_DYNAMIC_STORAGE_BIT);
  glVertexArrayVertexBuffer(vao, 3, m.single.id(), 0, 3 * sizeof(float));
  glEnableVertexArrayAttrib(vao, 3);
  glVertexArrayAttribFormat(vao, 3, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 3, 3);
  // Area lights' branches always compiled here: hierarchical.frag is one cheap pass.
  std::vector<std::string> defines = {"LUCENT_MAX_LIGHTS " + std::to_string(kMaxLights),
                                      "LUCENT_AREA_LIGHTS"};
  defines.push_back("LUCENT_MAX_AREA_LIGHTS " + std::to_string(gl::kMaxAreaLights));
  m.program = gl::Program(
      {{GL_VERTEX_SHADER, "hierarchical.vert"}, {GL_FRAGMENT_SHADER, "hierarchical.frag"}},
      defines);
  glProgramUniform1i(m.program.id(), m.program.location("u_environment"), GLint(kUnitEnvironment));
  m.final.build(scene, m.width, m.height, kUnitEnvironment);
  m.fit_bounds();
  m.upload_lights();
  glProgramUniform1f(m.program.id(), m.program.location("u_eta"), float(scene.material.ior));
  gl::set_angular_uniforms(m.program.id(), scene.material, scene.angular, false);
  gl::check_errors("hierarchical setup");
}

void HierarchicalRenderer::set_camera(const Camera& camera) {
  Impl& m = *impl_;
  if (camera.width != m.width || camera.height != m.height) {
    throw Error("hierarchical: the camera's size cannot change after setup");
  }
  m.scene.camera = camera;
}

void HierarchicalRenderer::set_lights(const std::vector<Light>& lights) {
  Impl& m = *impl_;
  m.scene.lights = lights;
  m.upload_lights();
  m.solver->set_lights(lights);
  m.single_valid = false;
}

void HierarchicalRenderer::set_material(const materials::Material& material) {
  Impl& m = *impl_;
  const materials::Material& had = m.scene.material;
  if (had.ior == material.ior && had.sigma_a == material.sigma_a &&
      had.sigma_s_reduced == material.sigma_s_reduced) {
    return;  // the same coefficients: the links stand
  }
  m.scene.material = material;
  m.solver->set_material(material);
  m.single_valid = false;
  glProgramUniform1f(m.program.id(), m.program.location("u_eta"), float(material.ior));
  gl::set_angular_uniforms(m.program.id(), material, m.scene.angular, false);
}

void HierarchicalRenderer::set_geometry(const std::vector<Vec3f>& positions,
                                        const std::vector<Vec3f>& normals) {
  Impl& m = *impl_;
  m.solver->set_geometry(positions, normals);
  gl::update_mesh(m.mesh, m.scene.mesh, positions, normals, "hierarchical");
  m.scene.mesh.positions = positions;
  m.scene.mesh.normals = normals;
  m.fit_bounds();
  m.rays.reset();
  m.single_valid = false;
}

void HierarchicalRenderer::setup(const Scene& scene, const TechniqueOptions& options) {
  setup(scene, options.hierarchical);
}

bool HierarchicalRenderer::converged() const {
  return impl_->frames > 0;
}

FrameStats HierarchicalRenderer::frame_stats() const {
  const Impl& m = *impl_;
  const hierarchical::Stats& s = m.solver->stats();
  FrameStats f;
  f.frames = m.frames;
  f.pass_ms = {{"link", s.link_ms},
               {"irradiance", s.irradiance_ms},
               {"gather+push", s.pull_ms + s.gather_ms + s.push_ms},
               {"single scattering", m.single_ms},
               {"draw", m.draw_ms}};
  f.notes.push_back(std::to_string(s.triangles) + " triangles, " + std::to_string(s.links) +
                    " links");
  return f;
}

bool HierarchicalRenderer::render_frame() {
  Impl& m = *impl_;
  m.solver->solve();
  m.update_single();
  double t0 = now_ms();
  const auto& vb = m.solver->vertex_B();
  m.B_floats.resize(vb.size() * 3);
  for (std::size_t v = 0; v < vb.size(); ++v)
    for (int c = 0; c < 3; ++c) m.B_floats[3 * v + std::size_t(c)] = float(vb[v][std::size_t(c)]);
  glNamedBufferSubData(m.B.id(), 0, GLsizeiptr(m.B_floats.size() * sizeof(float)), m.B_floats.data());
  glFinish();
  m.upload_ms = now_ms() - t0;

  t0 = now_ms();
  const detail::Mat4f view_proj = detail::camera_view_proj(m.scene.camera, m.centre, m.radius);
  m.final.begin_frame(view_proj, m.scene.backdrop);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  m.program.use();
  glUniformMatrix4fv(m.program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(m.program.location("u_eye"), 1, m.scene.camera.eye.data());
  glUniform1f(m.program.location("u_roughness"), m.scene.roughness);
  glUniform1i(m.program.location("u_specular"), m.scene.specular ? 1 : 0);
  glUniform1i(m.program.location("u_has_environment"), m.final.has_environment() ? 1 : 0);
  m.mesh.draw();
  glDisable(GL_DEPTH_TEST);
  glFinish();
  m.draw_ms = now_ms() - t0;
  ++m.frames;
  gl::check_errors("a hierarchical frame");
  return true;
}

ImageRgb HierarchicalRenderer::read_image() const {
  return impl_->final.read_image();
}

std::vector<std::uint8_t> HierarchicalRenderer::read_mask() const {
  return impl_->final.read_mask();
}

void HierarchicalRenderer::present(float exposure, int x, int y, int width, int height) const {
  impl_->final.present(exposure, x, y, width, height);
}

const hierarchical::Stats& HierarchicalRenderer::stats() const {
  return impl_->solver->stats();
}
double HierarchicalRenderer::upload_ms() const { return impl_->upload_ms; }
double HierarchicalRenderer::draw_ms() const { return impl_->draw_ms; }
double HierarchicalRenderer::single_scattering_ms() const {
  return impl_->single_ms;
}
const hierarchical::Solver& HierarchicalRenderer::solver() const {
  return *impl_->solver;
}

ImageRgb render_hierarchical(const Scene& scene, const hierarchical::Options& options,
                             RenderStats* stats) {
  const double t0 = now_ms();
  const auto context = GlContext::create_headless();
  HierarchicalRenderer renderer;
  renderer.setup(scene, options);
  renderer.render_frame();
  ImageRgb image = renderer.read_image();
  if (stats != nullptr) {
    const hierarchical::Stats& s = renderer.stats();
    stats->technique = "hierarchical";
    stats->width = scene.camera.width;
    stats->height = scene.camera.height;
    stats->total_ms = now_ms() - t0;
    stats->pass_ms = {{"hierarchy", s.build_ms},
                      {"link", s.link_ms},
                      {"irradiance", s.irradiance_ms},
                      {"pull", s.pull_ms},
                      {"gather", s.gather_ms},
                      {"push", s.push_ms},
                      {"single scattering", renderer.single_scattering_ms()},
                      {"upload", renderer.upload_ms()},
                      {"draw", renderer.draw_ms()}};
    stats->details = {{"triangles", s.triangles},
                      {"clusters", s.clusters},
                      {"depth", s.depth},
                      {"links", s.links},
                      {"form_factor_calls", s.form_factor_calls},
                      {"point_samples", s.point_samples},
                      {"edge_segments", s.edge_segments},
                      {"single_scattering", scene.single_scattering},
                      {"angular", scene.angular},
                      {"geometry_factor", scene.geometry_factor},
                      {"timing", "one frame from scratch (hierarchy, links, solve), wall clock"},
                      {"options", options.to_string()}};
  }
  return image;
}

}  // namespace lucent::render
