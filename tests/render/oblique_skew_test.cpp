// The oblique beam's skew of a radial profile (materials::oblique_skew, angular.h): each ring about
// the entry keeps its total and leans toward the refracted beam by the amount measured by Monte
// Carlo; its GLSL twin (angular.glsl) against the C++; and the reference with it against the path
// tracer on the issue's sun scene at eta 1, where light enters the sphere without bending toward
// the normal: the truth no diffusion model enters.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "gl_bssrdf.h"
#include "gl_fixture.h"
#include "gl_kernel.h"
#include "gl_program.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/material.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

using Vec3d = Eigen::Vector3d;

TEST(ObliqueSkew, BesselI0MatchesTheStandardLibrary) {
  for (const double a : {0.0, 0.1, 0.5, 1.0, 1.6, 2.0})
    EXPECT_NEAR(materials::bessel_i0(a), std::cyl_bessel_i(0.0, a), 1e-9 * std::cyl_bessel_i(0.0, a));
}

// On a plane: the mean of the skew over each ring is 1 (the profile's total, and so a plane under
// uniform light, unchanged) and its mean cos(phi) toward the beam is I_1 / I_0(a): 0.3-0.4 of
// sin(theta_t) within a few mean free paths, less far out at high albedo (Monte Carlo: 0.25-0.5,
// 0.15-0.23 at 16 mean free paths). Along the normal, or with entry and exit mirror images of each
// other (reciprocity), there is none.
TEST(ObliqueSkew, KeepsEachRingAndLeansTowardTheBeam) {
  const double l = 1.0, sigma_tr = 0.1;  // alpha' 0.9965, in mean free paths
  const Vec3d n = Vec3d::UnitZ();
  const double theta = 60 * std::numbers::pi / 180;
  const Vec3d w(std::sin(theta), 0, std::cos(theta));  // toward the light, on the +x side
  const Vec3d shift = materials::oblique_displacement(w, n, 1.0);
  EXPECT_NEAR(shift.norm(), std::sin(theta), 1e-12);
  EXPECT_LT(shift.x(), 0);  // the beam travels away from the light's side
  for (const double r : {0.05, 0.5, 2.0, 5.0, 16.0}) {
    constexpr int kSteps = 720;
    double mean = 0, lean = 0;
    for (int k = 0; k < kSteps; ++k) {
      const double phi = 2 * std::numbers::pi * (k + 0.5) / kSteps;
      const Vec3d x = r * Vec3d(std::cos(phi), std::sin(phi), 0);
      const double s = materials::oblique_skew(x, shift, l, sigma_tr);
      ASSERT_GT(s, 0);
      mean += s / kSteps;
      lean += s * (-std::cos(phi)) / kSteps;  // toward -x, where the beam goes
    }
    EXPECT_NEAR(mean, 1.0, 1e-9) << r;
    const double per_sin = lean / std::sin(theta);
    std::printf("r %.2f mean free paths: ring's mean cos toward the beam / sin(theta_t) %.3f\n", r,
                per_sin);
    EXPECT_GT(per_sin, r < 4 ? 0.3 : 0.12) << r;
    EXPECT_LT(per_sin, 0.45) << r;
  }
  EXPECT_EQ(materials::oblique_skew(Vec3d(1, 0, 0), materials::oblique_displacement(n, n, 1.3), l,
                                    sigma_tr),
            1.0);
  // Reciprocity: entry and exit swapped (x -> -x, w_i <-> w_o) give the same value.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 100; ++k) {
    const Vec3d x(u(rng), u(rng), 0.1 * u(rng)), w_i = Vec3d(u(rng), u(rng), 1).normalized(),
                w_o = Vec3d(u(rng), u(rng), 1).normalized();
    const Vec3d d_i = materials::oblique_displacement(w_i, n, 1.3),
                d_o = materials::oblique_displacement(w_o, n, 1.3);
    EXPECT_NEAR(materials::oblique_skew(x, Vec3d(d_i - d_o), l, sigma_tr),
                materials::oblique_skew(Vec3d(-x), Vec3d(d_o - d_i), l, sigma_tr), 1e-12);
  }
}

class ObliqueSkewGlslTest : public testing_gl::GlTest {};

constexpr const char* kKernel = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "angular.glsl"
layout(std430, binding = 0) readonly buffer Inputs { float in_data[]; };
layout(std430, binding = 1) writeonly buffer Outputs { float out_data[]; };
uniform int u_count;
vec3 load3(int b) { return vec3(in_data[b], in_data[b + 1], in_data[b + 2]); }
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  vec3 s = oblique_skew(load3(6 * i), load3(6 * i + 3));
  out_data[3 * i] = s.x;
  out_data[3 * i + 1] = s.y;
  out_data[3 * i + 2] = s.z;
}
)glsl";

TEST_F(ObliqueSkewGlslTest, MatchesTheCpp) {
  LUCENT_SKIP_WITHOUT_GL();
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::array<Vec3d, 2>> configs;
  for (int k = 0; k < 4000; ++k) {
    const double r = 0.01 * std::pow(3000.0, 0.5 * (u(rng) + 1));  // 0.01-30 mm
    const Vec3d x = r * Vec3d(u(rng), u(rng), u(rng)).normalized();
    const Vec3d shift = Vec3d(u(rng), u(rng), u(rng)).normalized() * (1.0 + u(rng));  // |.| 0-2
    configs.push_back({x, shift});
  }
  std::vector<float> input;
  for (const auto& c : configs)
    for (const Vec3d& v : c)
      for (int k = 0; k < 3; ++k) input.push_back(float(v[k]));
  const gl::Program program =
      gl::Program::from_source(GL_COMPUTE_SHADER, "oblique_skew_test.comp", kKernel, {});
  for (const char* name : {"skin1", "marble"}) {
    const materials::Material material = materials::load_material(name);
    gl::set_angular_uniforms(program.id(), material, true);
    const std::vector<float> result =
        testing_gl::run_kernel(program, input, configs.size(), 3, "oblique_skew_test kernel");
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
      const auto d = materials::derive_coefficients(material.medium(c));
      for (std::size_t k = 0; k < configs.size(); ++k) {
        auto f = [](const Vec3d& v) { return Vec3d(v.cast<float>().cast<double>()); };
        const double expected = materials::oblique_skew(f(configs[k][0]), f(configs[k][1]),
                                                        1 / d.sigma_t_reduced, d.sigma_tr);
        const double got = result[3 * k + std::size_t(c)];
        ASSERT_TRUE(std::isfinite(got)) << name << " " << c << " " << k;
        worst = std::max(worst, std::abs(got - expected) / expected);
      }
    }
    std::printf("%s: GLSL oblique skew vs C++ double, worst relative error %.3g\n", name, worst);
    EXPECT_LT(worst, 1e-4) << name;  // float exp and sums of a few terms
  }
  // Off (u_angular false): exactly 1.
  gl::set_angular_uniforms(program.id(), materials::load_material("skin1"), false);
  const std::vector<float> off =
      testing_gl::run_kernel(program, input, configs.size(), 3, "oblique_skew_test kernel");
  for (const float v : off) ASSERT_EQ(v, 1.0f);
}

// The issue's sun scene: a 15 mm potato sphere at eta 1 lit from the camera's side, 32 px, the
// surface reflection off, the reference (tabulated) with the angular terms against the path tracer.
// Without the skew the radial profile keeps the light that enters near the terminator, travelling
// on toward the far side, on the lit side: 1.18-1.24 of the truth at 64 px; with it 0.99-1.00
// with the former shape's factor, 1.04-1.07 with the osculating sphere's (materials/
// geometry_factor.h), which is closer to Monte Carlo on the sphere (an oblique beam's total there
// 0.83-0.99 of the truth's, the former 0.9-1.07) and so uncovers an excess of the angular terms'
// at eta 1 (measured at 32 px: 1.04 / 1.05 / 1.07; the reciprocal exit side is a third of the
// skew's correction).
TEST(ObliqueSkew, ReferenceMatchesThePathTracerAtEtaOne) {
  Scene scene;
  scene.mesh = load_mesh("sphere:3", 15.0);
  scene.material = materials::load_material("potato");
  scene.material.ior = 1.0;
  scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, 32, 32);
  scene.specular = false;
  scene.single_scattering = true;  // as the CLI renders by default
  scene.geometry_factor = true;
  Light light;
  light.direction = Vec3f(0.4f, 0.5f, 1).normalized();
  scene.lights = {light};
  PathTraceOptions po;
  po.pixel_samples = 192;
  po.threads = 2;
  const PathTraceImage truth = render_pathtrace(scene, po);
  ReferenceOptions ro;
  ro.pixel_samples = 256;
  ro.threads = 2;
  std::array<double, 2> worst{};
  scene.angular = true;
  for (const bool skew : {false, true}) {
    scene.oblique_skew = skew;
    const ReferenceImage ref = render_reference(scene, materials::DiffusionModel::kTabulated, ro);
    const ImageDifference d = compare_images(ref.image, truth.image, truth.mask);
    for (int c = 0; c < 3; ++c) {
      const double ratio = d.mean_ratio[std::size_t(c)];
      std::printf("skew %s, channel %d: reference / truth %.3f (truth +-%.3f)\n",
                  skew ? "on" : "off", c, ratio,
                  truth.object_mean_error[std::size_t(c)] / truth.object_mean[std::size_t(c)]);
      worst[skew] = std::max(worst[skew], std::abs(ratio - 1));
    }
  }
  EXPECT_LT(worst[1], 0.09);  // the issue's 10% target (measured 0.073)
  EXPECT_GT(worst[0], 0.10);  // the test sees what it fixes

  // The maps (the entry's skew in the gather, the exit's by a displaced read in the final pass) at
  // K 8, N 16 of M 256, W 64, 8 frames: measured 1.06 / 1.07 / 1.06 at 32 px (the shape's factor
  // from the entry's side: the gather does not know the view; 1.07-1.08 with a normal exit).
  std::string why_not;
  if (!GlContext::try_create_headless(&why_not)) GTEST_SKIP() << "no headless OpenGL: " << why_not;
  RenderSettings settings;
  settings.model = materials::DiffusionModel::kTabulated;
  settings.directions = 8;
  settings.samples = 16;
  settings.disc_points = 256;
  settings.frames = 8;
  settings.radiance_map_size = 64;
  settings.light_map_size = 128;
  scene.oblique_skew = true;
  const ImageDifference maps =
      compare_images(render_radiance_maps(scene, settings), truth.image, truth.mask);
  for (int c = 0; c < 3; ++c) {
    std::printf("maps, channel %d: / truth %.3f\n", c, maps.mean_ratio[std::size_t(c)]);
    EXPECT_NEAR(maps.mean_ratio[std::size_t(c)], 1.0, 0.1) << c;  // the issue's 10% target
  }
}

}  // namespace
}  // namespace lucent::render
