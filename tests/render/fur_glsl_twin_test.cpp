// The fur's GLSL against its C++ (Klotzli & Olano and our coat extension): fur_shade.glsl's 25-term
// reconstruction from the packed transfer texture (fur_gl.h) against fur::shade on thousands of
// (voxel, light) configurations, and fur_coat.glsl against FurCoat::at; the vertex frames and the
// lights' SH in them (fur_renderer.h); fur over a sphere finite, non-black, deterministic and
// shading the skin under it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fur_gl.h"
#include "gl_bssrdf.h"
#include "gl_fixture.h"
#include "gl_program.h"
#include "lucent/materials/material.h"
#include "lucent/render/fur.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/radiance_maps.h"

namespace lucent::render {
namespace {

constexpr const char* kKernel = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "fur_shade.glsl"
#include "fur_coat.glsl"
layout(std430, binding = 0) readonly buffer Inputs { float in_data[]; };
layout(std430, binding = 1) writeonly buffer Outputs { float out_data[]; };
uniform sampler2DArray u_transfer;
uniform int u_count;
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  int b = i * 79;  // u, v, shell, mu, then 3 x 25 coefficients
  vec4 r[7], g[7], bl[7];
  for (int k = 0; k < 7; ++k) {
    for (int c = 0; c < 4; ++c) {
      int j = 4 * k + c;
      r[k][c] = j < 25 ? in_data[b + 4 + j] : 0.0;
      g[k][c] = j < 25 ? in_data[b + 29 + j] : 0.0;
      bl[k][c] = j < 25 ? in_data[b + 54 + j] : 0.0;
    }
  }
  FurTexel f = fur_fetch(u_transfer, vec2(in_data[b], in_data[b + 1]), int(in_data[b + 2]));
  vec3 light = fur_light(f, r, g, bl);
  out_data[5 * i] = light.r;
  out_data[5 * i + 1] = light.g;
  out_data[5 * i + 2] = light.b;
  out_data[5 * i + 3] = fur_coverage(f);
  out_data[5 * i + 4] = fur_coat(in_data[b + 3]);
}
)glsl";

class FurGlslTwinTest : public testing_gl::GlTest {};

TEST_F(FurGlslTwinTest, ReconstructionAndCoatMatchTheCpp) {
  LUCENT_SKIP_WITHOUT_GL();
  fur::FurOptions o;
  o.texels = 12;
  o.shells = 6;
  o.overcoat.hairs = 30;
  o.undercoat.hairs = 120;
  const fur::FurTile tile = fur::make_fur_tile(o, 2);
  const FurCoat coat = fur::coat_transmittance(tile, o.optical_density, 16, 8, 2);
  constexpr int kCount = 4000;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> texel(0, o.texels - 1), shell(0, o.shells - 1);
  struct Config {
    int x, y, s;
    double mu;
    std::array<ShVector<double>, 3> light;
  };
  std::vector<Config> configs(kCount);
  std::vector<float> input;
  for (Config& c : configs) {
    c.x = texel(rng);
    c.y = texel(rng);
    c.s = shell(rng);
    c.mu = 0.6 * u(rng) + 0.5;  // -0.1 .. 1.1: both ends clamp
    input.push_back(float((c.x + 0.5) / o.texels));
    input.push_back(float((c.y + 0.5) / o.texels));
    input.push_back(float(c.s));
    input.push_back(float(c.mu));
    c.mu = double(float(c.mu));
    for (auto& channel : c.light)
      for (double& v : channel) {
        v = double(float(u(rng)));
        input.push_back(float(v));
      }
  }
  const gl::Program program = gl::Program::from_source(GL_COMPUTE_SHADER, "fur_twin.comp", kKernel);
  const gl::Texture transfer = detail::upload_fur_transfer(tile);
  gl::Sampler sampler = detail::fur_sampler();
  gl::Buffer in = gl::create_buffer(), out = gl::create_buffer();
  glNamedBufferStorage(in.id(), GLsizeiptr(input.size() * sizeof(float)), input.data(), 0);
  glNamedBufferStorage(out.id(), GLsizeiptr(kCount * 5 * sizeof(float)), nullptr, GL_MAP_READ_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
  glBindTextureUnit(0, transfer.id());
  glBindSampler(0, sampler.id());
  program.use();
  glUniform1i(program.location("u_transfer"), 0);
  glUniform1i(program.location("u_count"), kCount);
  gl::set_fur_coat_uniforms(program.id(), coat);
  glDispatchCompute(GLuint((kCount + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> result(std::size_t(kCount) * 5);
  glGetNamedBufferSubData(out.id(), 0, GLsizeiptr(result.size() * sizeof(float)), result.data());
  gl::check_errors("fur twin kernel");
  double worst_light = 0, worst_coverage = 0, worst_coat = 0;
  for (int i = 0; i < kCount; ++i) {
    const Config& c = configs[std::size_t(i)];
    const float* t = &tile.transfer[((std::size_t(c.s) * o.texels + c.y) * o.texels + c.x) * kShCoefficients];
    for (int ch = 0; ch < 3; ++ch) {
      // Relative to the sum of the terms' magnitudes: the random lights cancel.
      double scale = 0;
      for (int k = 0; k < kShCoefficients; ++k) scale += std::abs(c.light[std::size_t(ch)][std::size_t(k)] * t[k]);
      const double cpu = fur::shade(tile, c.s, c.y, c.x, c.light[std::size_t(ch)]);
      const double e = std::abs(result[std::size_t(5 * i + ch)] - cpu) / std::max(scale, 1e-30);
      worst_light = std::max(worst_light, e);
    }
    worst_coverage = std::max(worst_coverage, double(std::abs(result[std::size_t(5 * i + 3)] - tile.at(c.s, c.y, c.x))));
    const double coat_cpu = coat.at(c.mu);
    worst_coat = std::max(worst_coat, std::abs(result[std::size_t(5 * i + 4)] - coat_cpu) /
                                          std::max(coat_cpu, 1e-3));
  }
  std::printf("fur twin: %d configurations: light %.2e of the terms, coverage %.2e, coat %.2e\n",
              kCount, worst_light, worst_coverage, worst_coat);
  EXPECT_LT(worst_light, 1e-5);
  EXPECT_LT(worst_coverage, 1e-6);
  EXPECT_LT(worst_coat, 1e-4);
}

TEST(FurVertexFrame, IsARotationWithTheNormalUpAndTurnsTheLight) {
  std::mt19937_64 rng(3);
  std::normal_distribution<float> g(0, 1);
  for (int k = 0; k < 200; ++k) {
    Vec3f n(g(rng), g(rng), g(rng));
    if (k == 0) n = Vec3f(0, 1, 0);  // the poles
    if (k == 1) n = Vec3f(0, -1, 0);
    n.normalize();
    const Eigen::Matrix3d R = fur_vertex_frame(n);
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9) << k;
    EXPECT_NEAR(R.determinant(), 1.0, 1e-9) << k;
    EXPECT_LT((R.row(2).transpose() - n.cast<double>()).norm(), 1e-6) << k;
    // A directional light along the normal is the zonal delta about local +z.
    Light light;
    light.direction = n;
    light.radiance = Vec3f(2, 2, 2);
    const auto c = fur_light_sh({light}, Vec3f::Zero(), R);
    const ShVector<double> y = sh_basis<double>(0.0, 0.0, 1.0);
    for (int i = 0; i < kShCoefficients; ++i) EXPECT_NEAR(c[0][std::size_t(i)], 2 * y[std::size_t(i)], 1e-5);
  }
  // Continuous away from the poles: normals 0.01 rad apart give frames 0.01-ish apart.
  const Vec3f a = Vec3f(1, 0.2f, 0.3f).normalized(), b = Vec3f(1, 0.21f, 0.3f).normalized();
  EXPECT_LT((fur_vertex_frame(a) - fur_vertex_frame(b)).norm(), 0.05);
}

// Fur over a sphere (48 px, 8 shells): finite, deterministic, brighter than black, the shells
// visible over the skin (the image differs from the coated skin alone), and the skin under the coat
// darker than the bare skin by about the coat's T at the lit pole.
TEST_F(FurGlslTwinTest, FurOverASphereCoversTheSkin) {
  LUCENT_SKIP_WITHOUT_GL();
  Scene scene;
  scene.mesh = load_mesh("sphere", 100);
  scene.material = materials::load_material("skin1");
  scene.lights = {parse_light("directional:0,0,1:1,1,1")};
  scene.camera = orbit_camera(scene.mesh, 0, 0, 2.5f, 48, 48);
  scene.specular = false;
  fur::FurOptions o;
  o.texels = 16;
  o.shells = 8;
  o.overcoat.hairs = 60;
  o.undercoat.hairs = 240;
  o.tile_mm = 6;
  o.height_mm = 2;
  RenderSettings settings;
  settings.directions = 4;
  settings.samples = 16;
  settings.frames = 4;
  settings.radiance_map_size = settings.light_map_size = 64;
  RenderStats stats;
  const ImageRgb a = render_fur(scene, o, &stats, settings), b = render_fur(scene, o, nullptr, settings);
  EXPECT_EQ(a.data, b.data);
  for (float v : a.data) ASSERT_TRUE(std::isfinite(v));
  const ImageRgb bare = render_radiance_maps(scene, settings);
  Scene coated = scene;
  coated.fur_coat = fur::make_fur_coat(fur::over_mesh(o));
  const ImageRgb skin = render_radiance_maps(coated, settings);
  double sum_fur = 0, sum_skin = 0, sum_bare = 0, differ = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    sum_fur += a.data[i];
    sum_skin += skin.data[i];
    sum_bare += bare.data[i];
    differ += std::abs(a.data[i] - skin.data[i]);
  }
  const double T1 = coated.fur_coat->at(1.0);
  std::printf("fur over a sphere: fur %.4g, coated skin %.4g, bare skin %.4g (ratio %.3f, T(1) %.3f), "
              "fur vs skin %.3g; draw %.0f ms\n", sum_fur, sum_skin, sum_bare, sum_skin / sum_bare, T1,
              differ / sum_skin, stats.pass_ms.back().second);
  EXPECT_GT(sum_fur, 0);
  EXPECT_GT(differ / sum_skin, 0.01);  // the shells show
  // The light falls on the face the camera sees; cos_i spans 0..1 there, so the ratio lies
  // between the coat's T(mu) at grazing and at normal light.
  EXPECT_LT(sum_skin / sum_bare, T1 + 0.01);
  EXPECT_GT(sum_skin / sum_bare, 0.5 * T1);
}

}  // namespace
}  // namespace lucent::render
