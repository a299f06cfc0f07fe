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
#include "lucent/materials/angular.h"
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

// The factor against the truth: Monte Carlo of a normal beam into spheres and a half-space
// (notebooks_data/bench/sphere_factor_mc.py, numpy, independent of lucent's code), the ratio
// R_sphere(c) / R_plane(c) per chord c from the entry, lengths in mean free paths (sigma_t' = 1 per
// mm here). Held from 0.28 mean free paths to 1.6 radii: within 17% to 2 mean free paths, where
// most of the light leaves (measured worst 15.9%: a = 5, eta 1, alpha' 0.8, c = 1.7, 1.22
// for 1.45), within 35% to 4 (measured worst 33.5%: a = 10, eta 1.5, alpha' 0.8, c = 3.7, 2.11
// for 1.58, where the profile is down to a twentieth; at eta 1 it is short instead, 20% at a = 5,
// alpha' 0.8). The former modified-tangent-plane factor was 41% short at a = 3.4, alpha' 0.8, c
// = 3.4 (2.07 for 3.53) and 11.5% at alpha' 0.999, c = 1.36.
TEST(GeometryFactor, MatchesMonteCarloOnSpheres) {
  struct Case {
    double a, eta;
    std::vector<double> chord;
    std::array<std::vector<double>, 4> ratio;  // per alpha' below
  };
  const std::array<double, 4> albedos = {0.999, 0.99, 0.95, 0.8};
  const std::vector<Case> cases = {
      {1.5,
       1.0,
       {0.28, 0.351, 0.44, 0.552, 0.692, 0.867, 1.087, 1.363, 1.71, 2.143, 2.475, 2.625, 2.775},
       {{{1.177, 1.187, 1.218, 1.282, 1.331, 1.392, 1.519, 1.633, 1.826, 2.15, 2.6, 2.854, 3.317},
         {1.184, 1.195, 1.23, 1.297, 1.353, 1.423, 1.564, 1.699, 1.925, 2.303, 2.835, 3.133, 3.684},
         {1.204, 1.221, 1.266, 1.344, 1.423, 1.52, 1.708, 1.907, 2.245, 2.809, 3.628, 4.1, 4.946},
         {1.248, 1.275, 1.339, 1.445, 1.579, 1.743, 2.048, 2.425, 3.09, 4.226, 6.016, 7.126,
          9.143}}}},
      {3.4,
       1.3,
       {0.292, 0.397, 0.54, 0.735, 1.0, 1.36, 1.851, 2.519, 3.427},
       {{{1.138, 1.156, 1.21, 1.238, 1.307, 1.356, 1.431, 1.548, 1.701},
         {1.145, 1.164, 1.226, 1.259, 1.339, 1.403, 1.506, 1.665, 1.892},
         {1.16, 1.181, 1.259, 1.308, 1.417, 1.518, 1.689, 1.952, 2.385},
         {1.19, 1.209, 1.321, 1.408, 1.579, 1.76, 2.079, 2.567, 3.532}}}},
      {5.0,
       1.0,
       {0.297, 0.42, 0.595, 0.841, 1.189, 1.682, 2.378, 3.364},
       {{{1.045, 1.093, 1.089, 1.135, 1.125, 1.181, 1.215, 1.262},
         {1.048, 1.098, 1.096, 1.149, 1.146, 1.214, 1.271, 1.363},
         {1.054, 1.11, 1.112, 1.183, 1.196, 1.295, 1.403, 1.596},
         {1.064, 1.128, 1.14, 1.243, 1.289, 1.451, 1.661, 2.016}}}},
      {10.0,
       1.5,
       {0.308, 0.467, 0.707, 1.072, 1.625, 2.462, 3.732},
       {{{1.042, 1.075, 1.082, 1.124, 1.135, 1.165, 1.217},
         {1.045, 1.08, 1.089, 1.138, 1.158, 1.204, 1.292},
         {1.048, 1.087, 1.103, 1.16, 1.195, 1.261, 1.404},
         {1.056, 1.099, 1.135, 1.207, 1.253, 1.349, 1.579}}}},
  };
  double worst = 0;
  for (const Case& k : cases) {
    for (std::size_t j = 0; j < albedos.size(); ++j) {
      const Factor g(materials::derive_coefficients(
          materials::Medium<double>{1 - albedos[j], albedos[j], 0.0, k.eta}));
      for (std::size_t b = 0; b < k.chord.size(); ++b) {
        if (k.chord[b] > 1.6 * k.a || k.chord[b] > 4) continue;
        // The exit on the sphere at chord c from the entry at its pole.
        const double polar = 2 * std::asin(k.chord[b] / (2 * k.a));
        const SurfacePoint i = on_sphere(k.a, 0, 0), o = on_sphere(k.a, polar, 0.3);
        const double model = g(i.x, i.n, o.x, o.n), truth = k.ratio[j][b];
        worst = std::max(worst, std::abs(model / truth - 1));
        EXPECT_NEAR(model / truth, 1.0, k.chord[b] <= 2 ? 0.17 : 0.35)
            << "a " << k.a << " eta " << k.eta << " alpha' " << albedos[j] << " c " << k.chord[b];
      }
    }
  }
  std::printf("shape's factor against Monte Carlo on spheres: worst %.3f\n", worst);
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
  vec3 g = geometry_factor(load3(15 * i), load3(15 * i + 3), load3(15 * i + 6), load3(15 * i + 9),
                           load3(15 * i + 12));
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
    Vec3d x_i, n_i, w_i, x_o, n_o;  // w_i: toward the light (zero: a normal beam)
  };
  // A direction above n (a third of them none: the normal beam).
  auto beam = [&](const Vec3d& n) {
    if (u(rng) < 1.0 / 3) return Vec3d(Vec3d::Zero());
    Vec3d w = random_unit(rng);
    return Vec3d(w.dot(n) < 0 ? Vec3d(w - 2 * w.dot(n) * n) : w);
  };
  std::vector<Pair> pairs;
  for (int k = 0; k < 4000; ++k) {
    if (k % 2 == 0) {  // on spheres of 3-100 mm, both points anywhere
      const double a = 3 * std::pow(33.0, u(rng));
      const SurfacePoint i = on_sphere(a, std::acos(1 - 2 * u(rng)), 2 * std::numbers::pi * u(rng));
      const SurfacePoint o = on_sphere(a, std::acos(1 - 2 * u(rng)), 2 * std::numbers::pi * u(rng));
      pairs.push_back({i.x, i.n, beam(i.n), o.x, o.n});
    } else {  // random pairs 0.01-30 mm apart
      const double d = 0.01 * std::pow(3000.0, u(rng));
      const Vec3d n_i = random_unit(rng), n_o = random_unit(rng);
      pairs.push_back({Vec3d::Zero(), n_i, beam(n_i), d * random_unit(rng), n_o});
    }
  }
  const gl::Program program =
      gl::Program::from_source(GL_COMPUTE_SHADER, "geometry_factor_test.comp", kKernel, {});
  for (const char* name : {"skin1", "marble"}) {
    const materials::Material material = materials::load_material(name);
    const double eta = material.medium(0).eta;
    // The float inputs the shader sees, so that only its arithmetic is compared.
    auto f = [](const Vec3d& v) { return Vec3d(v.cast<float>().cast<double>()); };
    std::vector<Vec3d> beams;  // d_i per pair
    std::vector<float> input;
    for (const Pair& p : pairs) {
      const Vec3d d_i = f(materials::oblique_displacement(p.w_i, p.n_i, eta));
      beams.push_back(d_i);
      for (const Vec3d* v : {&p.x_i, &p.n_i, &d_i, &p.x_o, &p.n_o})
        for (int k = 0; k < 3; ++k) input.push_back(float((*v)[k]));
    }
    gl::set_geometry_factor_uniforms(program.id(), material, true);
    const std::vector<float> result =
        testing_gl::run_kernel(program, input, pairs.size(), 3, "geometry_factor_test kernel");
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
      const Factor g(materials::derive_coefficients(material.medium(c)));
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const Pair& p = pairs[k];
        const double expected = g.from_entry(f(p.x_i), f(p.n_i), beams[k], f(p.x_o), f(p.n_o));
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
// included). Measured at 32 px (channel means over the truth's): front 0.74-0.79 without, 1.03-1.10
// with; behind 0.46-0.52 without, 1.02-1.07 with. (The former modified-tangent-plane factor gave
// 0.83-0.86 and 0.77-0.88: it under-gave a small sphere's far field.)
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
        // Within the issue's 10% of the truth; blue (alpha' 0.82) front-lit 10% over, measured.
        EXPECT_NEAR(ratio, 1.0, 0.12) << (behind ? "behind " : "front ") << c;
      }
    }
    EXPECT_LT(worst[1], worst[0] - (behind ? 0.3 : 0.1)) << (behind ? "behind" : "front");
  }
}

}  // namespace
}  // namespace lucent::render
