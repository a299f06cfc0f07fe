// The SH fast translucency technique on the GPU (render/techniques/sh/sh_renderer.cpp,
// render/techniques/sh/shaders/sh_*): the GLSL twin of sh_translucency.h, the GPU projection
// against the CPU one (a constant, a linear function, a rendered cube map), the thickness pass
// against the analytic chord of a sphere, finiteness, determinism, deforming meshes, and the image
// against the CPU reference after a best-fit scale (the technique is not physically based). Skipped
// without headless OpenGL 4.5.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "gl_api.h"
#include "gl_fixture.h"
#include "gl_program.h"
#include "lucent/materials/material.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "lucent/render/sh_renderer.h"
#include "sh_translucency.h"

namespace lucent::render {
namespace {

using Vec3d = Eigen::Vector3d;

class ShRendererTest : public testing_gl::GlTest {
 protected:
  void SetUp() override {
    if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  }

  // A sphere of 100 mm bounding-box diagonal seen from +z at 3 radii.
  static Scene sphere_scene(int size, const std::string& light,
                            const std::string& material = "marble") {
    Scene scene;
    scene.mesh = load_mesh("sphere", 100);
    scene.material = materials::load_material(material);
    scene.lights = {parse_light(light)};
    scene.camera = orbit_camera(scene.mesh, 0, 0, 3, size, size);
    scene.specular = false;
    return scene;
  }

};


// ---- the GLSL twin ----------------------------------------------------------------------------

constexpr int kInputs = 20;   // q (3), e (9), d, sigma_tr, sigma_t', origin (3), direction (3)
constexpr int kOutputs = 18;  // Y (9), B, a, exit (3), lookup (3), texel weight
constexpr const char* kTwinKernel = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "sh_math.glsl"
layout(std430, binding = 0) readonly buffer Inputs { float in_data[]; };
layout(std430, binding = 1) writeonly buffer Outputs { float out_data[]; };
uniform int u_count;
uniform vec3 u_box_min, u_box_max;
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  int b = i * 20, o = i * 18;
  vec3 q = vec3(in_data[b], in_data[b + 1], in_data[b + 2]);
  float y[9];
  sh_basis(q, y);
  for (int k = 0; k < 9; ++k) out_data[o + k] = y[k];
  float e[27];
  for (int k = 0; k < 27; ++k) e[k] = k < 9 ? in_data[b + 3 + k] : 0.0;
  out_data[o + 9] = sh_irradiance(sh_irradiance_matrix(e, 0), q);
  out_data[o + 10] = sh_attenuation(in_data[b + 12], in_data[b + 13], in_data[b + 14]);
  vec3 origin = vec3(in_data[b + 15], in_data[b + 16], in_data[b + 17]);
  vec3 dir = normalize(vec3(in_data[b + 18], in_data[b + 19], q.x));
  vec3 p = sh_ray_box_exit(u_box_min, u_box_max, origin, dir);
  vec3 l = sh_box_lookup_direction(u_box_min, u_box_max, p);
  for (int k = 0; k < 3; ++k) out_data[o + 11 + k] = p[k];
  for (int k = 0; k < 3; ++k) out_data[o + 14 + k] = l[k];
  int w = 64, ti = i % 64, tj = (i / 64) % 64;
  out_data[o + 17] = sh_texel_weight(sh_texel_centre(ti, w), sh_texel_centre(tj, w), w);
}
)glsl";

TEST_F(ShRendererTest, GlslTwinMatchesTheCppMath) {
  const int n = 4096;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
  std::vector<float> in(std::size_t(n) * kInputs);
  const Vec3d box_min(-30, -12, -5), box_max(25, 18, 40);
  for (int i = 0; i < n; ++i) {
    float* v = &in[std::size_t(i) * kInputs];
    Eigen::Vector3f q(u(rng), u(rng), u(rng));
    q.normalize();
    for (int k = 0; k < 3; ++k) v[k] = q[k];
    for (int k = 0; k < 9; ++k) v[3 + k] = u(rng) * (k == 0 ? 4.0f : 1.0f);
    v[12] = std::pow(10.0f, 3.0f * unit(rng) - 2.5f);  // d 0.003..3 mm: the guard's range
    v[13] = std::pow(10.0f, 2.0f * unit(rng) - 2.0f);  // sigma_tr 0.01..1 /mm
    v[14] = std::pow(10.0f, 2.0f * unit(rng) - 1.0f);  // sigma_t' 0.1..10 /mm
    for (int k = 0; k < 3; ++k) {
      v[15 + k] = float(box_min[k] + (box_max[k] - box_min[k]) * unit(rng));
    }
    v[18] = u(rng), v[19] = u(rng);
  }
  const gl::Program program =
      gl::Program::from_source(GL_COMPUTE_SHADER, "sh_twin.comp", kTwinKernel);
  gl::Buffer inputs = gl::create_buffer(), outputs = gl::create_buffer();
  glNamedBufferStorage(inputs.id(), GLsizeiptr(in.size() * sizeof(float)), in.data(), 0);
  glNamedBufferStorage(outputs.id(), GLsizeiptr(std::size_t(n) * kOutputs * sizeof(float)),
                       nullptr, 0);
  program.use();
  glUniform1i(program.location("u_count"), n);
  const Eigen::Vector3f bmin = box_min.cast<float>(), bmax = box_max.cast<float>();
  glUniform3fv(program.location("u_box_min"), 1, bmin.data());
  glUniform3fv(program.location("u_box_max"), 1, bmax.data());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, inputs.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, outputs.id());
  glDispatchCompute(GLuint((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> out(std::size_t(n) * kOutputs);
  glGetNamedBufferSubData(outputs.id(), 0, GLsizeiptr(out.size() * sizeof(float)), out.data());
  gl::check_errors("sh twin");

  double worst_y = 0, worst_b = 0, worst_a = 0, worst_p = 0, worst_w = 0;
  for (int i = 0; i < n; ++i) {
    const float* v = &in[std::size_t(i) * kInputs];
    const float* g = &out[std::size_t(i) * kOutputs];
    const Vec3d q(v[0], v[1], v[2]);
    const auto y = sh::sh_basis(q);
    for (int k = 0; k < 9; ++k) worst_y = std::max(worst_y, std::abs(g[k] - y[std::size_t(k)]));
    sh::Coefficients<double> e{};
    double e_scale = 0;
    for (int k = 0; k < 9; ++k) e[std::size_t(k)] = v[3 + k], e_scale += std::abs(v[3 + k]);
    const double b = sh::irradiance(sh::irradiance_matrix(e), q);
    worst_b = std::max(worst_b, std::abs(g[9] - b) / e_scale);
    const double a = sh::attenuation<double>(v[12], v[13], v[14]);
    worst_a = std::max(worst_a, std::abs(g[10] - a) / a);
    const Vec3d origin(v[15], v[16], v[17]);
    const Vec3d dir = Vec3d(v[18], v[19], v[0]).normalized();
    const Vec3d p = sh::ray_box_exit(box_min, box_max, origin, dir);
    const Vec3d l = sh::box_lookup_direction(box_min, box_max, p);
    for (int k = 0; k < 3; ++k) {
      worst_p = std::max(worst_p, std::abs(g[11 + k] - p[k]) / 50.0);  // relative to the box
      worst_p = std::max(worst_p, std::abs(g[14 + k] - l[k]));
    }
    const double w = sh::texel_weight<double>(i % 64, (i / 64) % 64, 64);
    worst_w = std::max(worst_w, std::abs(g[17] - w) / w);
  }
  std::printf("GLSL twin, %d configurations: basis %.2e, B %.2e (of sum |E|), attenuation %.2e "
              "relative, box exit / look-up %.2e, texel weight %.2e relative\n",
              n, worst_y, worst_b, worst_a, worst_p, worst_w);
  EXPECT_LT(worst_y, 1e-6);
  EXPECT_LT(worst_b, 1e-5);
  EXPECT_LT(worst_a, 1e-4);
  EXPECT_LT(worst_p, 1e-4);
  EXPECT_LT(worst_w, 1e-5);
}

// ---- the projection ---------------------------------------------------------------------------

// Six faces of w^2 RGBA texels with channel values f_c(direction).
template <typename F>
std::vector<float> cube_of(int w, F&& f) {
  std::vector<float> rgba(std::size_t(w) * std::size_t(w) * 6 * 4);
  sh::for_each_cube_texel<double>(
      w, sh::TexelWeight::kDifferential,
      [&](sh::CubeFace face, int i, int j, const Vec3d& dir, double) {
        const std::size_t t =
            ((std::size_t(face) * std::size_t(w) + std::size_t(j)) * std::size_t(w) + std::size_t(i));
        const std::array<double, 3> v = f(dir);
        for (int c = 0; c < 3; ++c) rgba[t * 4 + std::size_t(c)] = float(v[std::size_t(c)]);
        rgba[t * 4 + 3] = 1;
      });
  return rgba;
}

// The CPU projection of a cube map laid out as read_cube_map() returns it.
sh::RgbCoefficients<double> cpu_projection(const std::vector<float>& rgba, int w) {
  sh::RgbCoefficients<double> out{};
  sh::for_each_cube_texel<double>(
      w, sh::TexelWeight::kDifferential,
      [&](sh::CubeFace face, int i, int j, const Vec3d& dir, double d_omega) {
        const std::size_t t =
            ((std::size_t(face) * std::size_t(w) + std::size_t(j)) * std::size_t(w) + std::size_t(i));
        const auto y = sh::sh_basis(dir);
        for (int c = 0; c < 3; ++c) {
          for (int k = 0; k < 9; ++k) {
            out[std::size_t(c)][std::size_t(k)] +=
                rgba[t * 4 + std::size_t(c)] * d_omega * y[std::size_t(k)];
          }
        }
      });
  return out;
}

TEST_F(ShRendererTest, GpuProjectsAConstantToE00AndALinearFunctionToE1m) {
  const int w = 32;
  const auto constant = project_cube_map_on_gpu(
      cube_of(w, [](const Vec3d&) { return std::array<double, 3>{1, 2, 3}; }), w);
  // E00 = c sqrt(4 pi) (1 + the weights' quadrature error, 2.4e-4 at W = 32).
  for (int c = 0; c < 3; ++c) {
    const double e00 = (c + 1) * 2 * std::sqrt(M_PI);
    EXPECT_NEAR(constant[std::size_t(c)][0], e00, 5e-4 * e00);
    for (int k = 1; k < 9; ++k) EXPECT_LT(std::abs(constant[std::size_t(c)][std::size_t(k)]), 1e-5 * e00);
  }
  // f = (x, y, z) in R, G, B: E11, E1-1, E10 = sqrt(4 pi / 3), all else 0.
  const auto linear = project_cube_map_on_gpu(
      cube_of(w, [](const Vec3d& d) { return std::array<double, 3>{d.x(), d.y(), d.z()}; }), w);
  const double e1 = std::sqrt(4 * M_PI / 3);
  const int expected[3] = {sh::sh_index(1, 1), sh::sh_index(1, -1), sh::sh_index(1, 0)};
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 9; ++k) {
      const float v = linear[std::size_t(c)][std::size_t(k)];
      if (k == expected[c]) {
        EXPECT_NEAR(v, e1, 1e-3 * e1) << "channel " << c;
      } else {
        EXPECT_LT(std::abs(v), 1e-5 * e1) << "channel " << c << " coefficient " << k;
      }
    }
  }
}

TEST_F(ShRendererTest, GpuProjectionOfARenderedCubeMapEqualsTheCpuProjection) {
  Scene scene = sphere_scene(32, "directional:1,0.4,0.3:1,0.8,0.6");
  scene.lights.push_back(parse_light("point:0,60,40:3000,3000,3000"));
  ShOptions options;
  options.cube_map_size = 32;
  options.shadow_map_size = 128;
  ShRenderer renderer;
  renderer.setup(scene, options);
  renderer.render_frame();
  const std::vector<float> cube = renderer.read_cube_map();
  std::size_t covered = 0;
  for (std::size_t t = 0; t < cube.size(); t += 4) covered += cube[t + 3] > 0;
  EXPECT_GT(covered, cube.size() / 4 / 2);  // a sphere covers pi/4 of each face
  const auto gpu = renderer.read_coefficients();
  const auto cpu = cpu_projection(cube, 32);
  double worst = 0;
  for (int c = 0; c < 3; ++c) {
    const double scale = std::abs(cpu[std::size_t(c)][0]);
    ASSERT_GT(scale, 0);
    for (int k = 0; k < 9; ++k) {
      worst = std::max(worst, std::abs(gpu[std::size_t(c)][std::size_t(k)] -
                                       cpu[std::size_t(c)][std::size_t(k)]) / scale);
    }
  }
  std::printf("GPU projection vs CPU on a rendered cube map: %.2e of |E00|\n", worst);
  EXPECT_LT(worst, 1e-4);
  // Light from +x: the +x side of the cube map is brighter, E11 > 0.
  EXPECT_GT(gpu[0][std::size_t(sh::sh_index(1, 1))], 0);
}

// ---- thickness --------------------------------------------------------------------------------

TEST_F(ShRendererTest, ThicknessOnASphereMatchesTheChordWithinATexel) {
  for (const std::string light : {"directional:1,0,0:1,1,1", "point:0,0,-150:1e4,1e4,1e4"}) {
    Scene scene = sphere_scene(48, light);
    ShOptions options;
    options.shadow_map_size = 256;
    options.depth_blur_sigma_texels = 0;  // the raw depth: the blur is a smoothing on purpose
    ShRenderer renderer;
    renderer.setup(scene, options);
    renderer.set_output(ShOutput::kThickness);
    renderer.render_frame();
    const ImageRgb thickness = renderer.read_image();
    const auto mask = renderer.read_mask();
    renderer.set_output(ShOutput::kPosition);
    renderer.render_frame();
    const ImageRgb position = renderer.read_image();

    const Mesh& mesh = scene.mesh;
    const Vec3d centre = mesh.centre().cast<double>();
    double radius = 0, min_radius = 1e30;
    for (const auto& p : mesh.positions) {
      radius = std::max(radius, (p.cast<double>() - centre).norm());
    }
    // The tessellation's faces lie inside the sphere by at most the sagitta: measure it at the
    // face centroids.
    for (const auto& t : mesh.triangles) {
      const Vec3d m = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]])
                          .cast<double>() / 3.0;
      min_radius = std::min(min_radius, (m - centre).norm());
    }
    const double sagitta = radius - min_radius;
    const double texel = renderer.stats().shadow_texel_mm;
    const Light& l = scene.lights[0];
    int pixels = 0, beyond = 0, wrong_lit = 0;
    double worst_excess = 0, sum_error = 0;
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 48; ++x) {
        if (!mask[std::size_t(y) * 48 + std::size_t(x)]) continue;
        const Vec3d p(position.at(x, y, 0), position.at(x, y, 1), position.at(x, y, 2));
        const Vec3d source = l.type == LightType::kPoint
                                 ? l.position.cast<double>()
                                 : Vec3d(p + 1e5 * l.direction.cast<double>().normalized());
        const Vec3d w = (source - p).normalized();
        const double d_true = sh::sphere_thickness(centre, radius, source, p);
        // How far the chord moves when the ray shifts by a texel sideways (steep at grazing),
        // plus a texel and the tessellation's sagitta twice (entry and exit faces).
        const Vec3d rel = p - centre;
        const double b = (rel - rel.dot(w) * w).norm();
        const auto chord = [&](double bb) {
          return bb >= radius ? 0.0 : 2 * std::sqrt(radius * radius - bb * bb);
        };
        const double slack =
            d_true > 0 ? std::max(std::abs(chord(b - texel) - chord(b)),
                                  std::abs(chord(std::min(b + texel, radius)) - chord(b)))
                       : 0.0;
        const double allowed = texel + 2 * sagitta + slack;
        const double error = std::abs(thickness.at(x, y, 0) - d_true);
        worst_excess = std::max(worst_excess, error / allowed);
        sum_error += error;
        ++pixels;
        beyond += thickness.at(x, y, 1) > 0.5;
        // Lit by the light iff the point faces it (by more than the tessellation's slack).
        const double facing = rel.normalized().dot(w);
        if (std::abs(facing) > 0.1 && (facing > 0) != (thickness.at(x, y, 2) > 0.5)) ++wrong_lit;
      }
    }
    std::printf("%s: %d pixels, mean |d - chord| %.3f mm, texel %.3f mm, sagitta %.3f mm, worst "
                "error / allowed %.2f\n",
                light.c_str(), pixels, sum_error / pixels, texel, sagitta, worst_excess);
    EXPECT_GT(pixels, 500);
    EXPECT_LE(worst_excess, 1.0) << light;
    EXPECT_EQ(beyond, 0) << light << ": a convex sphere has nothing beyond its second depth";
    EXPECT_EQ(wrong_lit, 0) << light;
  }
}

// ---- images -----------------------------------------------------------------------------------

TEST_F(ShRendererTest, FiniteNonNegativeDeterministicAndDeformable) {
  Scene scene = sphere_scene(32, "directional:0.3,0.2,-1:1,1,1");
  ShOptions options;
  options.shadow_map_size = 128;
  options.cube_map_size = 16;
  ShRenderer renderer;
  renderer.setup(scene, options);
  renderer.render_frame();
  const ImageRgb a = renderer.read_image();
  renderer.render_frame();
  const ImageRgb b = renderer.read_image();
  const auto mask = renderer.read_mask();
  int object = 0, positive = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a.data[i]));
    ASSERT_GE(a.data[i], 0.0f);
    ASSERT_EQ(a.data[i], b.data[i]) << "frame to frame";
    positive += a.data[i] > 0;
  }
  for (auto m : mask) object += m;
  EXPECT_GT(object, 200);
  EXPECT_GT(positive, object);  // most object pixels carry light in some channel

  // Squash the sphere to half its depth along the light: thinner, so brighter behind.
  Mesh squashed = scene.mesh;
  for (auto& p : squashed.positions) p.z() *= 0.5f;
  squashed.normals = area_weighted_normals(squashed);
  renderer.set_geometry(squashed.positions, squashed.normals);
  renderer.render_frame();
  const ImageRgb c = renderer.read_image();
  double before = 0, after = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) before += a.data[i], after += c.data[i];
  std::printf("deformed: image sum %.4g -> %.4g\n", before, after);
  EXPECT_GT(after, 1.05 * before);
}

// Side-lit: measured at 64 px against 2048 probes, correlation 0.87 (skin1). Back-lit spheres of
// this size are thick (d^-1 fall-off over tens of mm) and correlate 0.08-0.43 only; the bunny
// back-lit 0.68-0.76 (closing note of issue 12): this ctest holds the side-lit case.
TEST_F(ShRendererTest, CorrelatesWithTheReferenceSideLit) {
  for (const std::string light : {"directional:1,0.2,0:1,1,1"}) {
    Scene scene = sphere_scene(32, light, "skin1");
    scene.camera = orbit_camera(scene.mesh, 0, 0, 3, 32, 32);
    ShOptions options;
    options.shadow_map_size = 256;
    const ImageRgb sh_image = render_sh(scene, options);
    ReferenceOptions reference_options;
    reference_options.pixel_samples = 1024;
    const ReferenceImage reference =
        render_reference(scene, DiffusionModel::kDirectionalDipole, reference_options);
    const ScaledComparison fit = compare_scaled(sh_image, reference.image, reference.mask);
    std::printf("%s (skin1, 32 px): best scale %.4g, correlation %.3f, relative RMSE after the "
                "scale %.3f\n",
                light.c_str(), fit.scale, fit.correlation, fit.relative_rmse);
    EXPECT_TRUE(std::isfinite(fit.scale));
    EXPECT_GT(fit.scale, 0);
    EXPECT_GT(fit.correlation, 0.5) << light;
  }
}

}  // namespace
}  // namespace lucent::render
