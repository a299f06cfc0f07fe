// The shape's factor of multiple scattering (materials/geometry_factor.h): its limits (exactly 1 on
// a plane, reciprocal, above 1 on convex and below 1 on concave surfaces, finite everywhere), its
// GLSL twin (geometry_factor.glsl) against the C++, and the reference with it against the path
// tracer on a small sphere lit from the front and from behind: the truth no diffusion model enters.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include "gl_api.h"
#include "gl_bssrdf.h"
#include "gl_fixture.h"
#include "gl_kernel.h"
#include "gl_program.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/materials/material.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

using Vec3d = Eigen::Vector3d;
using Factor = materials::GeometryFactor<double>;

Factor factor_of(const char* material, int channel) {
  return Factor(materials::derive_coefficients(materials::load_material(material).medium(channel)));
}

Vec3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Vec3d v(n(rng), n(rng), n(rng));
  return v.normalized();
}

// A point on a sphere of radius a about the origin, and its outward normal.
struct SurfacePoint {
  Vec3d x, n;
};
SurfacePoint on_sphere(double a, double polar, double azimuth) {
  const Vec3d n(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                std::cos(polar));
  return {a * n, n};
}

TEST(GeometryFactor, IsExactlyOneOnAPlane) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const char* material : {"potato", "skin1", "marble", "ketchup"}) {
    for (int c = 0; c < 3; ++c) {
      const Factor g = factor_of(material, c);
      for (int k = 0; k < 200; ++k) {
        const double scale = std::pow(10.0, 2 * u(rng));  // 0.01-100 mm apart
        const Vec3d x_i(scale * u(rng), scale * u(rng), 0), x_o(scale * u(rng), scale * u(rng), 0);
        EXPECT_NEAR(g(x_i, Vec3d::UnitZ(), x_o, Vec3d::UnitZ()), 1.0, 1e-12)
            << material << " " << c << " " << (x_o - x_i).norm();
      }
    }
  }
}

TEST(GeometryFactor, IsReciprocalAndFinite) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  const Factor g = factor_of("skin1", 1);
  for (int k = 0; k < 2000; ++k) {
    const double scale = std::pow(10.0, 3 * u(rng));
    const Vec3d x_i = scale * Vec3d(u(rng), u(rng), u(rng)),
                x_o = scale * Vec3d(u(rng), u(rng), u(rng));
    const Vec3d n_i = random_unit(rng), n_o = random_unit(rng);
    const double forward = g(x_i, n_i, x_o, n_o), back = g(x_o, n_o, x_i, n_i);
    ASSERT_TRUE(std::isfinite(forward) && forward >= 0 && forward <= Factor::kMax) << forward;
    EXPECT_NEAR(forward, back, 1e-12 * std::max(1.0, forward));
  }
  // The degenerate cases: one point; the far side straight through; a medium that does not scatter.
  EXPECT_EQ(g(Vec3d::Zero(), Vec3d::UnitZ(), Vec3d::Zero(), -Vec3d::UnitZ()), 1.0);
  EXPECT_TRUE(std::isfinite(g(Vec3d::Zero(), Vec3d::UnitZ(), Vec3d(0, 0, -1e4), -Vec3d::UnitZ())));
  const Factor clear(materials::derive_coefficients(materials::Medium<double>{0.1, 0.0, 0.0, 1.3}));
  EXPECT_EQ(clear(Vec3d::Zero(), Vec3d::UnitZ(), Vec3d(0, 0, -3), -Vec3d::UnitZ()), 1.0);
}

// On a sphere of radius a (outward normals: convex), near the entry point the light leaves through
// a surface that turns toward the way it diffuses: G > 1; on the far side it crosses the exit
// surface head-on: G larger still. Seen from inside a spherical cavity (inward normals: concave),
// G < 1 near the entry. Both tend to 1 as the sphere grows (a plane). (In between, a few diffusion
// lengths away at 60-70 degrees round a large sphere, the tilt of the exit surface takes G a little
// below 1: the model's, not checked here.)
TEST(GeometryFactor, ConvexAboveOneConcaveBelowOne) {
  const Factor g = factor_of("potato", 0);  // a diffusion length of ~14 mm
  for (const double a : {5.0, 15.0, 50.0}) {
    const SurfacePoint i = on_sphere(a, 0, 0);
    const SurfacePoint near = on_sphere(a, 0.2, 0.7), far = on_sphere(a, 3.0, 0.7);
    const double convex = g(i.x, i.n, near.x, near.n);
    EXPECT_GT(convex, 1.0) << a;
    EXPECT_GT(g(i.x, i.n, far.x, far.n), convex) << a;
    EXPECT_LT(g(i.x, -i.n, near.x, -near.n), 1.0) << a;
  }
  // The near field of a large sphere is nearly a plane.
  const SurfacePoint i = on_sphere(1000, 0, 0), o = on_sphere(1000, 0.005, 0);
  EXPECT_NEAR(g(i.x, i.n, o.x, o.n), 1.0, 0.01);
}

// The GLSL twin against the C++ in double, per channel, on spheres and on random pairs.
class GeometryFactorGlslTest : public testing_gl::GlTest {};

constexpr const char* kKernel = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "geometry_factor.glsl"
layout(std430, binding = 0) readonly buffer Inputs { float in_data[]; };
layout(std430, binding = 1) writeonly buffer Outputs { float out_data[]; };
uniform int u_count;
vec3 load3(int b) { return vec3(in_data[b], in_data[b + 1], in_data[b + 2]); }
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  vec3 g = geometry_factor(load3(12 * i), load3(12 * i + 3), load3(12 * i + 6), load3(12 * i + 9));
  out_data[3 * i] = g.x;
  out_data[3 * i + 1] = g.y;
  out_data[3 * i + 2] = g.z;
}
)glsl";

TEST_F(GeometryFactorGlslTest, MatchesTheCpp) {
  LUCENT_SKIP_WITHOUT_GL();
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> u(0, 1);
  struct Pair {
    Vec3d x_i, n_i, x_o, n_o;
  };
  std::vector<Pair> pairs;
  for (int k = 0; k < 4000; ++k) {
    if (k % 2 == 0) {  // on spheres of 3-100 mm, both points anywhere
      const double a = 3 * std::pow(33.0, u(rng));
      const SurfacePoint i = on_sphere(a, std::acos(1 - 2 * u(rng)), 2 * std::numbers::pi * u(rng));
      const SurfacePoint o = on_sphere(a, std::acos(1 - 2 * u(rng)), 2 * std::numbers::pi * u(rng));
      pairs.push_back({i.x, i.n, o.x, o.n});
    } else {  // random pairs 0.01-30 mm apart
      const double d = 0.01 * std::pow(3000.0, u(rng));
      pairs.push_back({Vec3d::Zero(), random_unit(rng), d * random_unit(rng), random_unit(rng)});
    }
  }
  std::vector<float> input;
  for (const Pair& p : pairs) {
    for (const Vec3d* v : {&p.x_i, &p.n_i, &p.x_o, &p.n_o})
      for (int k = 0; k < 3; ++k) input.push_back(float((*v)[k]));
  }
  const gl::Program program =
      gl::Program::from_source(GL_COMPUTE_SHADER, "geometry_factor_test.comp", kKernel, {});
  for (const char* name : {"skin1", "marble"}) {
    const materials::Material material = materials::load_material(name);
    gl::set_geometry_factor_uniforms(program.id(), material, true);
    const std::vector<float> result =
        testing_gl::run_kernel(program, input, pairs.size(), 3, "geometry_factor_test kernel");
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
      const Factor g(materials::derive_coefficients(material.medium(c)));
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const Pair& p = pairs[k];
        // The float inputs the shader saw, so that only its arithmetic is compared.
        auto f = [](const Vec3d& v) { return Vec3d(v.cast<float>().cast<double>()); };
        const double expected = g(f(p.x_i), f(p.n_i), f(p.x_o), f(p.n_o));
        const double got = result[3 * k + std::size_t(c)];
        ASSERT_TRUE(std::isfinite(got)) << name << " " << c << " " << k;
        worst = std::max(worst, std::abs(got - expected) / std::max(expected, 1e-3));
      }
    }
    std::printf("%s: GLSL geometry factor vs C++ double, worst relative error %.3g\n", name, worst);
    EXPECT_LT(worst, 2e-3) << name;  // float: e^(s0 - s) and the images' difference
  }
}

// The reference with and without the factor against the path tracer: a potato sphere of 10 mm
// (0.7 diffusion lengths in red, 3.4 mean free paths in radius) at 32 px, lit from the camera's
// side and from behind, the surface reflection off, the angular terms on (the oblique skew
// included). Measured at 32 px (channel means over the truth's): front 0.74-0.79 without, 0.83-0.86
// with; behind 0.46-0.52 without, 0.77-0.88 with. Front-lit, the factor is short of the truth's
// on so small a sphere: against Monte Carlo of a normal beam on a sphere of 3.4 mean free paths it
// gives 1.37 where the truth is 2.15 at 5.5 mean free paths from the entry (1.12 / 1.46 at 3.5),
// where the oblique skew sends the light entering near the terminator (docs/DESIGN.md §4.4).
TEST(GeometryFactor, ReferenceComesCloserToThePathTracer) {
  Scene scene;
  scene.mesh = load_mesh("sphere:3", 10.0);
  scene.material = materials::load_material("potato");
  scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, 32, 32);
  scene.specular = false;
  scene.single_scattering = true;
  scene.angular = true;
  PathTraceOptions po;
  po.pixel_samples = 192;
  po.threads = 2;
  ReferenceOptions ro;
  ro.pixel_samples = 256;
  ro.threads = 2;
  for (const bool behind : {false, true}) {
    Light light;
    light.direction = (behind ? Vec3f(0, 0.2f, -1) : Vec3f(0.4f, 0.5f, 1)).normalized();
    scene.lights = {light};
    scene.geometry_factor = false;
    const PathTraceImage truth = render_pathtrace(scene, po);
    std::array<double, 2> worst{};
    for (const bool on : {false, true}) {
      scene.geometry_factor = on;
      const ReferenceImage ref = render_reference(scene, materials::DiffusionModel::kTabulated, ro);
      const ImageDifference d = compare_images(ref.image, truth.image, truth.mask);
      for (int c = 0; c < 3; ++c) {
        const double ratio = d.mean_ratio[std::size_t(c)];
        std::printf("%s, factor %s, channel %d: reference / truth %.3f (truth +-%.3f)\n",
                    behind ? "behind" : "front", on ? "on" : "off", c, ratio,
                    truth.object_mean_error[std::size_t(c)] / truth.object_mean[std::size_t(c)]);
        worst[on] = std::max(worst[on], std::abs(ratio - 1));
        if (!on) continue;
        if (behind) {
          EXPECT_NEAR(ratio, 0.8, 0.15) << c;  // an eighth to a quarter still missing
        } else {
          EXPECT_NEAR(ratio, 0.85, 0.06) << c;  // the factor's deficit above, measured
        }
      }
    }
    EXPECT_LT(worst[1], worst[0] - (behind ? 0.2 : 0.04)) << (behind ? "behind" : "front");
  }
}

}  // namespace
}  // namespace lucent::render
