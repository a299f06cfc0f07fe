// render/core/irradiance_cache.h: Jacob's per-cluster projection maps of area-light irradiance
// against direct evaluation at the same points (area_light_irradiance.h with the same shadow
// rays), on a sphere under a rect (curved clusters, the terminator where the rect straddles the
// horizon) and on a box beside a second box (a cast shadow: penumbrae); and in the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "area_light.h"
#include "irradiance_cache.h"
#include "lucent/materials/material.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "slab_scene.h"

namespace lucent::render::detail {
namespace {

Light sphere_rect() {
  const Vec3f c(50, 50, 40);
  const Vec3f n = -c.normalized();
  const Vec3f u = 25.0f * Vec3f(n.unitOrthogonal());
  const Vec3f v = 25.0f * Vec3f(n.cross(u).normalized());
  return rect_light(c, u, v, Vec3f(1, 1, 1));
}

struct CacheError {
  double mean = 0, p95 = 0;  // of |cache - direct| / max direct, over the points
  IrradianceCacheStats stats;
};

// Random surface points (uniform over faces' area), cache against direct with 256 rays each.
CacheError measure(const Mesh& mesh, const std::vector<Light>& lights, double texel_mm) {
  const RayScene rays(mesh);
  IrradianceCacheOptions options;
  options.texel_mm = texel_mm;
  options.shadow_samples = 256;
  const IrradianceCache cache(mesh, lights, &rays, 1.5, options);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<double> areas;
  for (const auto& t : mesh.triangles) {
    areas.push_back((mesh.positions[t[1]] - mesh.positions[t[0]])
                        .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                        .norm());
  }
  std::discrete_distribution<std::size_t> pick(areas.begin(), areas.end());
  std::vector<double> got, want;
  double peak = 0;
  for (int k = 0; k < 1500; ++k) {
    const std::size_t f = pick(rng);
    float a = u(rng), b = u(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const auto& t = mesh.triangles[f];
    const Vec3f x = (1 - a - b) * mesh.positions[t[0]] + a * mesh.positions[t[1]] +
                    b * mesh.positions[t[2]];
    got.push_back(cache.lookup(f, x)[0]);
    want.push_back(cache.direct(f, x)[0]);
    peak = std::max(peak, want.back());
  }
  std::vector<double> errors;
  for (std::size_t i = 0; i < got.size(); ++i) errors.push_back(std::abs(got[i] - want[i]) / peak);
  std::sort(errors.begin(), errors.end());
  CacheError e;
  for (double x : errors) e.mean += x / double(errors.size());
  e.p95 = errors[errors.size() * 95 / 100];
  e.stats = cache.stats();
  return e;
}

TEST(IrradianceCache, ConvergesToDirectEvaluationOnASphere) {
  const Mesh mesh = load_mesh("sphere:3", 100);  // 1280 triangles, radius 28.9 mm
  double previous = 1;
  for (double texel : {4.0, 2.0, 1.0}) {
    const CacheError e = measure(mesh, {sphere_rect()}, texel);
    std::printf("cache sphere texel %.1f mm: %zu clusters, %zu grid vertices, %zu evaluated; error "
                "mean %.2e p95 %.2e of the peak\n",
                texel, e.stats.clusters, e.stats.grid_vertices, e.stats.evaluated, e.mean, e.p95);
    EXPECT_GT(e.stats.clusters, 6u);  // a sphere needs several 30-degree cones
    EXPECT_LT(e.stats.evaluated, e.stats.grid_vertices + 1);  // lazily
    EXPECT_LT(e.mean, previous);      // converges as the texel shrinks
    previous = e.mean;
  }
  EXPECT_LT(previous, 0.01);
}

// Two boxes on a floor under a rect: the tall one casts a soft shadow on the floor.
Mesh boxes() {
  Mesh m;
  testing_slab::add_box(m, {-60, -5, -60}, {60, 0, 60});  // the floor slab
  testing_slab::add_box(m, {-10, 0, -10}, {10, 40, 10});  // the tall box
  return m;
}

TEST(IrradianceCache, PenumbraOnAFloor) {
  const Mesh mesh = boxes();
  const std::vector<Light> lights = {parse_light("rect:30,70,0:15,0,0:0,0,15:1,1,1")};
  double previous = 1;
  for (double texel : {4.0, 1.0}) {
    const CacheError e = measure(mesh, lights, texel);
    std::printf("cache boxes texel %.1f mm: %zu clusters, %zu grid vertices; error mean %.2e p95 "
                "%.2e of the peak\n",
                texel, e.stats.clusters, e.stats.grid_vertices, e.mean, e.p95);
    EXPECT_EQ(e.stats.clusters, 12u);  // the boxes' faces: one plane each
    EXPECT_LT(e.mean, previous);
    previous = e.mean;
  }
  EXPECT_LT(previous, 0.01);
}

TEST(IrradianceCache, ReferenceWithTheCacheMatchesWithout) {
  Scene scene;
  scene.mesh = load_mesh("sphere:3", 100);
  scene.material = materials::load_material("marble");
  scene.specular = false;
  scene.lights = {sphere_rect()};
  scene.camera = orbit_camera(scene.mesh, 100, 10, 3.4f, 24, 24);
  ReferenceOptions options;
  options.pixel_samples = 128;
  options.threads = 2;
  options.area_light_samples = 16;
  const ReferenceImage direct = render_reference(scene, materials::DiffusionModel::kDipole, options);
  options.irradiance_cache = true;
  const ReferenceImage cached = render_reference(scene, materials::DiffusionModel::kDipole, options);
  const ImageDifference d = compare_images(cached.image, direct.image, direct.mask);
  std::printf("reference with the cache vs without: %s\n", d.to_string().c_str());
  EXPECT_LT(d.relative_rmse, 0.02);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(d.mean_ratio[std::size_t(c)], 1.0, 0.01);
}

}  // namespace
}  // namespace lucent::render::detail
