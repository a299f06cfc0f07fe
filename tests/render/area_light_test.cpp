// Area lights (Jacob 1993) in the renderers: the GLSL form factor
// (render/gl/shaders/form_factor.glsl) held to the C++ (polygon_form_factor.h) on thousands of
// configurations; a wide slab under a large parallel rect against its truth, for the reference and
// the radiance maps; maps against the reference on a sphere lit by a rect (soft shadows, penumbra).
//
// The slab's truth: on a plane, the radiance at the lit face's centre x_0 for a radial model is
//
//   L(x_0) = (1 / pi) integral over the face of E_t(x) P(|x - x_0|) dA,
//   E_t(x) = L_rect integral over the rect's solid angle from x of F_t(eta, cos theta) cos theta
//   dw,
//
// P the model's normal-incidence profile of pi L per unit power entering (slab_scene.h). E_t is a
// midpoint quadrature over the rect (cells 2 mm, 30 mm away), the face integral a trapezoid in
// ln r with 8 angles per radius (E_t varies slowly). Under an infinite rect E_t is L times the
// integral of F_t cos over the hemisphere, and L(x_0) reduces to the issue's F_t(0) (R_tot / pi)
// L times that integral (checked below for the dipole).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <random>
#include <utility>
#include <string>
#include <vector>

#include "area_light.h"
#include "gl_api.h"
#include "gl_fixture.h"
#include "gl_kernel.h"
#include "gl_program.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/profile_table.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/tone_map.h"
#include "polygon_form_factor.h"
#include "slab_scene.h"

namespace lucent::render {
namespace {

using materials::DiffusionModel;
using V = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

class AreaLightGlTest : public testing_gl::GlTest {
 protected:
};

// ---------------------------------------------------------------------------------------------
// The GLSL twin.

constexpr int kVertices = 8;
constexpr int kStride = 3 + 3 + 1 + 3 * kVertices;  // x, n, count, vertices
constexpr int kOutputs = 5;                          // F, vector (3), clipped area

constexpr const char* kKernel = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "form_factor.glsl"
layout(std430, binding = 0) readonly buffer Inputs { float in_data[]; };
layout(std430, binding = 1) writeonly buffer Outputs { float out_data[]; };
uniform int u_count;
vec3 load3(int b) { return vec3(in_data[b], in_data[b + 1], in_data[b + 2]); }
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  int b = i * STRIDE;
  vec3 x = load3(b), n = load3(b + 3);
  int count = int(in_data[b + 6]);
  vec3 p[LUCENT_MAX_POLYGON_VERTICES];
  for (int k = 0; k < LUCENT_MAX_POLYGON_VERTICES; ++k) p[k] = load3(b + 7 + 3 * k);
  FormFactor f = polygon_form_factor(x, n, p, count);
  out_data[5 * i] = f.F;
  out_data[5 * i + 1] = f.vector_.x;
  out_data[5 * i + 2] = f.vector_.y;
  out_data[5 * i + 3] = f.vector_.z;
  out_data[5 * i + 4] = f.clipped_area;
}
)glsl";

double to_float(double v) {
  volatile float f = static_cast<float>(v);
  return f;
}

TEST_F(AreaLightGlTest, GlslFormFactorMatchesTheCpp) {
  if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  struct Config {
    V x, n;
    std::vector<V> polygon;
  };
  std::vector<Config> configs;
  // Regular polygons of 3..8 vertices, 5-200 mm across, 2-400 mm from a receiver of any normal
  // (so that a third or so straddle its horizon and some are behind it).
  for (int i = 0; i < 6000; ++i) {
    Config c;
    c.x = V(100 * u(rng), 100 * u(rng), 100 * u(rng));
    c.n = V(u(rng), u(rng), u(rng)).normalized();
    const int count = 3 + i % 6;
    const double size = 5 * std::pow(40.0, 0.5 * (u(rng) + 1));
    const double distance = 2 * std::pow(200.0, 0.5 * (u(rng) + 1));
    const V centre = c.x + distance * V(u(rng), u(rng), u(rng)).normalized();
    const V axis = V(u(rng), u(rng), u(rng)).normalized();
    const V e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
    for (int k = 0; k < count; ++k) {
      const double phi = 2 * kPi * k / count;
      c.polygon.push_back(centre + 0.5 * size * (std::cos(phi) * e1 + std::sin(phi) * e2));
    }
    // Inputs as the GPU sees them (float), so that only the arithmetic differs.
    for (int k = 0; k < 3; ++k) c.x[k] = to_float(c.x[k]), c.n[k] = to_float(c.n[k]);
    for (V& p : c.polygon)
      for (int k = 0; k < 3; ++k) p[k] = to_float(p[k]);
    configs.push_back(c);
  }
  std::vector<float> input(configs.size() * kStride, 0.0f);
  for (std::size_t i = 0; i < configs.size(); ++i) {
    float* p = &input[i * kStride];
    for (int k = 0; k < 3; ++k) p[k] = float(configs[i].x[k]), p[3 + k] = float(configs[i].n[k]);
    p[6] = float(configs[i].polygon.size());
    for (std::size_t v = 0; v < configs[i].polygon.size(); ++v)
      for (int k = 0; k < 3; ++k) p[7 + 3 * v + std::size_t(k)] = float(configs[i].polygon[v][k]);
  }
  const gl::Program program = gl::Program::from_source(
      GL_COMPUTE_SHADER, "form_factor_twin.comp", kKernel, {"STRIDE " + std::to_string(kStride)});
  const std::vector<float> result =
      testing_gl::run_kernel(program, input, configs.size(), kOutputs, "form factor twin");

  // F relative to itself where it matters (|F| >= 1e-3, a light that delivers anything); the
  // vector relative to the contour's total angle sum_i angle_i / 2 pi everywhere: a polygon seen
  // nearly edge-on has F and |vector| -> 0 by cancellation of O(1) terms, where float can only
  // promise an error relative to the terms.
  double worst_F = 0, worst_vector = 0, worst_area = 0, worst_twin = 0;
  int straddling = 0, zero = 0, lit = 0;
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const Config& c = configs[i];
    const auto cpu = polygon_form_factor<double>(c.x, c.n, std::span<const V>(c.polygon));
    double angles = 0;
    for (std::size_t k = 0; k < c.polygon.size(); ++k) {
      const V a = c.polygon[k] - c.x, b = c.polygon[(k + 1) % c.polygon.size()] - c.x;
      angles += std::atan2(a.cross(b).norm(), a.dot(b));
    }
    const V gpu_vector(result[i * kOutputs + 1], result[i * kOutputs + 2], result[i * kOutputs + 3]);
    if (std::abs(cpu.F) >= 1e-3) {
      ++lit;
      worst_F = std::max(worst_F, std::abs(result[i * kOutputs] / cpu.F - 1));
    }
    worst_vector = std::max(worst_vector, (gpu_vector - cpu.vector).norm() / (angles / (2 * kPi)));
    // The same function in float on the CPU: the twin's own fidelity, apart from float itself.
    std::vector<Eigen::Vector3f> pf;
    for (const V& p : c.polygon) pf.push_back(p.cast<float>());
    const auto f32 = polygon_form_factor<float>(c.x.cast<float>(), c.n.cast<float>(),
                                                std::span<const Eigen::Vector3f>(pf));
    worst_twin = std::max(worst_twin, (gpu_vector - f32.vector.cast<double>()).norm() /
                                          (angles / (2 * kPi)));
    const double full_area =
        polygon_form_factor<double>(c.x, c.n, std::span<const V>(c.polygon), false).clipped_area;
    worst_area =
        std::max(worst_area, std::abs(result[i * kOutputs + 4] - cpu.clipped_area) / full_area);
    straddling += cpu.clipped_area > 0 && cpu.clipped_area < 0.999 * full_area;
    zero += cpu.clipped_area == 0;
  }
  std::printf("form factor twin: %zu configurations (%d straddling, %d behind, %d with |F| >= "
              "1e-3): worst F %.2e (relative), vector %.2e (of the contour's angle; %.2e against "
              "the C++ in float), clipped area %.2e (of the area)\n",
              configs.size(), straddling, zero, lit, worst_F, worst_vector, worst_twin, worst_area);
  EXPECT_GT(straddling, 500);
  EXPECT_GT(zero, 500);
  EXPECT_GT(lit, 1000);
  EXPECT_LT(worst_F, 1e-4);
  // Float itself: the C++ template in float is off from double by the same 1.0e-4 (straddling
  // polygons around the receiver's normal, clip vertices 100 mm away); the twin matches it.
  EXPECT_LT(worst_vector, 2e-4);
  EXPECT_LT(worst_twin, 1e-5);
  EXPECT_LT(worst_area, 1e-4);
}

// ---------------------------------------------------------------------------------------------
// The slab under a rect.

// E_t / L at x (normal +y) from the rect light: midpoint rule on m x m cells.
double transmitted_per_radiance(const V& x, const Light& rect, double eta, int m = 60) {
  const V p0 = rect.polygon[0].cast<double>(), du = (rect.polygon[1] - rect.polygon[0]).cast<double>(),
          dv = (rect.polygon[3] - rect.polygon[0]).cast<double>();
  const V normal = du.cross(dv).normalized();
  const double cell = du.cross(dv).norm() / (double(m) * m);
  double sum = 0;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const V p = p0 + (i + 0.5) / m * du + (j + 0.5) / m * dv;
      const V d = p - x;
      const double r2 = d.squaredNorm(), r = std::sqrt(r2);
      const double cos_x = d.y() / r, cos_p = -normal.dot(d) / r;
      if (cos_x <= 0 || cos_p <= 0) continue;
      sum += materials::fresnel_transmittance(cos_x, eta) * cos_x * cos_p / r2 * cell;
    }
  }
  return sum;
}

struct RectSlab {
  testing_slab::SlabScene slab;
  Light rect;
};

// The slab of slab_scene.h (face at y = 25, 200 x 200 mm) under a 120 x 120 mm rect 30 mm above
// it, facing down, radiance 1; the camera's field narrowed to 1 degree (+-2.6 mm of the centre,
// over which E_t varies by < 0.05%).
RectSlab make_rect_slab(const std::string& material, int pixels) {
  RectSlab s{testing_slab::make_slab_scene(material, pixels), {}};
  s.rect = parse_light("rect:0,55,0:60,0,0:0,0,60:1,1,1");
  s.slab.scene.lights = {s.rect};
  s.slab.scene.camera.fov_y_deg = 1;
  return s;
}

double rect_slab_truth(const RectSlab& s, DiffusionModel model, int c) {
  const materials::Material& m = s.slab.scene.material;
  const double h = s.slab.half_width_mm;
  const int radii = 300, angles = 8;
  const double lo = 1e-6 * h, hi = h * std::sqrt(2.0), step = std::log(hi / lo) / (radii - 1);
  double sum = 0;
  for (int i = 0; i < radii; ++i) {
    const double r = lo * std::exp(step * i);
    double ring = 0;
    for (int k = 0; k < angles; ++k) {
      const double phi = 2 * kPi * (k + 0.5) / angles;
      const double x = r * std::cos(phi), z = r * std::sin(phi);
      if (std::abs(x) > h || std::abs(z) > h) continue;
      ring += transmitted_per_radiance(V(x, 25, z), s.rect, m.ior, 40);
    }
    ring *= 2 * kPi / angles;
    const double P = materials::radial_profile_value(m, c, model, materials::TableQuantity::kRadiance, r);
    sum += (i == 0 || i == radii - 1 ? 0.5 : 1.0) * P * ring * r * r;  // P ring r dr = .. r^2 d ln r
  }
  return sum * step / kPi;
}

TEST(AreaLightSlab, TruthQuadratureChecks) {
  const double eta = materials::load_material("marble").ior;
  // With F_t = 1 (eta = 1) the quadrature of E_t is pi F (the catalogue-checked contour sum).
  const Light rect = parse_light("rect:0,55,0:60,0,0:0,0,60:1,1,1");
  std::array<V, 4> q;
  for (int i = 0; i < 4; ++i) q[std::size_t(i)] = rect.polygon[std::size_t(i)].cast<double>();
  const double F = polygon_form_factor<double>(V(3, 25, -2), V::UnitY(), q).F;
  EXPECT_NEAR(transmitted_per_radiance(V(3, 25, -2), rect, 1.0, 200) / (kPi * F), 1.0, 1e-4);
  // Under a rect far wider than its height (400 mm half-width at 2 mm: 89.7 degrees), E_t is the
  // integral of F_t cos over the hemisphere, so that the truth is the issue's F_t(0) (R_tot / pi) L
  // times it.
  const Light wide = parse_light("rect:0,27,0:400,0,0:0,0,400:1,1,1");
  double hemisphere = 0;  // 2 pi integral of F_t(mu) mu d mu
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double mu = (i + 0.5) / n;
    hemisphere += materials::fresnel_transmittance(mu, eta) * mu;
  }
  hemisphere *= 2 * kPi / n;
  EXPECT_NEAR(transmitted_per_radiance(V(0, 25, 0), wide, eta, 3000) / hemisphere, 1.0, 2e-3);
}

TEST(AreaLightSlab, ReferenceMatchesTheTruth) {
  for (const char* material : {"marble", "skin1"}) {
    for (const DiffusionModel model : {DiffusionModel::kDipole, DiffusionModel::kTabulated}) {
      const RectSlab s = make_rect_slab(material, 8);
      ReferenceOptions options;
      options.pixel_samples = 64;
      options.threads = 2;
      const ReferenceImage reference = render_reference(s.slab.scene, model, options);
      for (int ch = 0; ch < 3; ++ch) {
        const double truth = rect_slab_truth(s, model, ch);
        const double got = testing_slab::centre_mean(reference.image, ch);
        std::printf("rect slab reference %-7s %-9s ch %d: %.6g vs truth %.6g: %+.2f%%\n", material,
                    materials::to_string(model).c_str(), ch, got, truth, 100 * (got / truth - 1));
        EXPECT_NEAR(got / truth, 1.0, 0.03) << material << " " << materials::to_string(model);
      }
    }
  }
}

// Measured (K 8, N 16 of M 256, 16 frames, W 64): marble +1.2..+1.4%, skin1 +0.7..+0.9% (both
// models): the Fresnel factor taken at the form factor's vector direction, where the truth
// averages F_t over the rect (lower at its grazing parts). Bound: the issue's 4%.
TEST_F(AreaLightGlTest, RadianceMapsMatchTheSlabTruth) {
  if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  for (const auto& [material, model] : {std::pair{"marble", DiffusionModel::kDipole},
                                        std::pair{"skin1", DiffusionModel::kTabulated}}) {
    {
      const RectSlab s = make_rect_slab(material, 8);
      RenderSettings settings;
      settings.model = model;
      settings.directions = 8;
      settings.samples = 16;
      settings.disc_points = 256;
      settings.frames = 16;
      settings.radiance_map_size = settings.light_map_size = 64;
      const ImageRgb image = render_radiance_maps(s.slab.scene, settings);
      for (int ch = 0; ch < 3; ++ch) {
        const double truth = rect_slab_truth(s, model, ch);
        const double got = testing_slab::centre_mean(image, ch);
        std::printf("rect slab maps %-7s %-9s ch %d: %.6g vs truth %.6g: %+.2f%%\n", material,
                    materials::to_string(model).c_str(), ch, got, truth, 100 * (got / truth - 1));
        EXPECT_NEAR(got / truth, 1.0, 0.04) << material << " " << materials::to_string(model);
      }
    }
  }
}

// A 100 mm marble sphere (sphere:3) lit by a 50 x 50 mm rect 80 mm from its centre, seen from the
// side so that the terminator (where the rect straddles the horizon) crosses the image; the
// reference at 256 probes per pixel against the maps at the tiny settings above. Measured: 5.2%
// relative RMSE, channel means +0.4%. Bound: the issue's 10% (means: 5%).
Scene rect_sphere_scene() {
  Scene scene;
  scene.mesh = load_mesh("sphere:3", 100);
  scene.material = materials::load_material("marble");
  scene.specular = false;
  const Vec3f c(50, 50, 40);
  const Vec3f n = -c.normalized();
  const Vec3f u = 25.0f * Vec3f(n.unitOrthogonal());
  const Vec3f v = 25.0f * Vec3f(n.cross(u).normalized());
  scene.lights = {rect_light(c, u, v, Vec3f(2, 2, 2))};
  scene.camera = orbit_camera(scene.mesh, 100, 10, 3.4f, 48, 48);
  return scene;
}

TEST_F(AreaLightGlTest, MapsMatchTheReferenceOnASphere) {
  if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_;
  const Scene scene = rect_sphere_scene();
  EXPECT_NEAR(area_light_normal(scene.lights[0]).dot(-scene.lights[0].position.normalized()), 1.0,
              1e-5);  // emits toward the sphere
  ReferenceOptions options;
  options.pixel_samples = 256;
  options.threads = 2;
  const ReferenceImage reference = render_reference(scene, DiffusionModel::kDipole, options);
  RenderSettings settings;
  settings.model = DiffusionModel::kDipole;
  settings.directions = 8;
  settings.samples = 16;
  settings.disc_points = 256;
  settings.frames = 16;
  settings.radiance_map_size = settings.light_map_size = 64;
  const ImageRgb maps = render_radiance_maps(scene, settings);
  const ImageDifference d = compare_images(maps, reference.image, reference.mask);
  std::printf("rect sphere maps vs reference: %s\n", d.to_string().c_str());
  if (const char* dir = std::getenv("LUCENT_TEST_IMAGES")) {  // to look at them
    ToneMapOptions tone;
    tone.exposure = auto_exposure(reference.image, reference.mask);
    write_render_image(std::string(dir) + "/rect_sphere_reference.png", reference.image, tone);
    write_render_image(std::string(dir) + "/rect_sphere_maps.png", maps, tone);
  }
  EXPECT_LT(d.relative_rmse, 0.10);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(d.mean_ratio[std::size_t(c)], 1.0, 0.05);
}

}  // namespace
}  // namespace lucent::render
