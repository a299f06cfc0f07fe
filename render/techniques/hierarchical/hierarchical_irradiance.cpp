// The leaves' irradiance of the hierarchical technique (hierarchical_irradiance.h).
#include "hierarchical_irradiance.h"

#include <algorithm>
#include <cstdint>

#include "area_light_irradiance.h"
#include "lucent/materials/fresnel.h"
#include "reference_common.h"

namespace lucent::render::hierarchical {
namespace {

using Rgb = std::array<double, 3>;
// Shadow rays per face (or per cache grid vertex) for an area light (area_light_irradiance.h):
// with the control variate only faces whose horizon cuts the light are noisy; on a 100 mm sphere
// under a 50 mm rect the cache and per-leaf rays agree to 0.5% in E, 0.3% in B
// (hierarchical_solver_test).
constexpr int kAreaLightSamples = 16;

}  // namespace

void leaf_irradiance(const Scene& scene, bool shadows, bool use_cache, double eta,
                     const materials::AngularFactor* angular, detail::RayScene* rays,
                     std::unique_ptr<detail::IrradianceCache>& cache, std::vector<Rgb>& face_E) {
  const Mesh& mesh = scene.mesh;
  const float eps = 1e-4f * std::max(mesh.bounding_radius(), 1e-6f);
  const std::size_t T = mesh.triangles.size();
  face_E.assign(T, Rgb{});
  const bool any_area = std::any_of(scene.lights.begin(), scene.lights.end(),
                                    [](const Light& l) { return l.type == LightType::kArea; });
  if (any_area && use_cache && !cache) {
    detail::IrradianceCacheOptions co;
    co.shadow_samples = kAreaLightSamples;
    co.shadows = shadows;
    co.coat = scene.fur_coat ? &*scene.fur_coat : nullptr;
    cache = std::make_unique<detail::IrradianceCache>(mesh, scene.lights, rays, eta, co);
  }
  for (std::size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3f &a = mesh.positions[tri[0]], &b = mesh.positions[tri[1]],
                &d = mesh.positions[tri[2]];
    const Vec3f x = (a + b + d) / 3.0f;
    Vec3f g = (b - a).cross(d - a);
    if (!(g.norm() > 0)) continue;
    g.normalize();
    Vec3f n = mesh.normals[tri[0]] + mesh.normals[tri[1]] + mesh.normals[tri[2]];
    n = n.norm() > 0 ? Vec3f(n.normalized()) : g;
    if (cache) {
      const auto E = cache->lookup(t, x);
      for (int ch = 0; ch < 3; ++ch)
        face_E[t][std::size_t(ch)] += std::max(E[std::size_t(ch)], 0.0);
    }
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const Light& light = scene.lights[l];
      if (light.type == LightType::kArea) {
        if (cache) continue;
        // kAreaLightSamples stratified shadow rays with the analytic pi F as control variate
        // (area_light_irradiance.h), the same points every frame (no flicker); a penumbra's
        // rare negative estimate is clamped to 0.
        detail::AreaLightSampling sampling;
        sampling.samples = kAreaLightSamples;
        sampling.shadows = shadows;
        sampling.coat = scene.fur_coat ? &*scene.fur_coat : nullptr;
        const detail::AreaIrradiance a = detail::area_light_irradiance(
            light, x, n, g, rays, eps, eta, sampling,
            detail::mix(std::uint64_t(t) * 0x9E3779B97F4A7C15ull + l));
        const double f = std::max(a.transmitted, 0.0);
        const double cos_a = double(n.dot(a.w));
        for (int ch = 0; ch < 3; ++ch)
          face_E[t][std::size_t(ch)] +=
              f * light.radiance[ch] * (angular ? (*angular)(ch, cos_a) : 1.0);
        continue;
      }
      Vec3f w;
      double falloff = 1, distance = detail::kInf;
      if (!detail::toward_light(light, x, w, falloff, distance)) continue;
      const double cos_i = n.dot(w);
      if (!(cos_i > 0)) continue;
      if (shadows) {
        const Vec3f offset = g.dot(w) >= 0 ? g : Vec3f(-g);
        if (rays->occluded(x + eps * offset, w, distance - eps)) continue;
      }
      const double f = falloff * cos_i * materials::fresnel_transmittance(cos_i, eta) *
                       (scene.fur_coat ? scene.fur_coat->at(cos_i) : 1.0);
      for (int ch = 0; ch < 3; ++ch)
        face_E[t][std::size_t(ch)] +=
            f * light.radiance[ch] * (angular ? (*angular)(ch, cos_i) : 1.0);
    }
  }
}
}  // namespace lucent::render::hierarchical
