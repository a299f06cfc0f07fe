// The CPU reference's specular term (reference_renderer.h): every light's GGX lobe at a pixel's
// point (materials/specular.h) with shadow rays; area lights by stratified points on the polygon.
#include "area_light.h"
#include "lucent/materials/specular.h"
#include "reference_common.h"

namespace lucent::render::detail {

// The specular lobe of every light at a pixel's point (materials/specular.h), with a shadow ray.
// Area lights: the mean over kAreaSpecularSamples stratified points of the polygon (shadow ray,
// GGX, L cos_p / r^2 dA), unbiased like the subsurface term. Under a fur coat (fur_coat.h) the
// light reaching the surface is T(cos_i) of itself, as for the subsurface term.
constexpr int kAreaSpecularSamples = 16;

Vec3f specular_radiance(const Scene& scene, const RayScene& rays, const PixelHit& hit, float eps,
                        std::uint64_t key) {
  Vec3f sum = Vec3f::Zero();
  if (!scene.specular || !(scene.roughness > 0)) return sum;
  const double cos_o = hit.n_o.dot(hit.w_o);
  if (!(cos_o > 0)) return sum;
  const auto lobe = [&](const Vec3f& w, double cos_i) {
    const Vec3f h = (w + hit.w_o).normalized();
    return materials::ggx_reflection<double>(cos_i, cos_o, hit.n_o.dot(h), h.dot(w),
                                             scene.roughness, scene.material.ior) *
           (scene.fur_coat ? scene.fur_coat->at(cos_i) : 1.0);
  };
  for (const Light& light : scene.lights) {
    if (light.type == LightType::kArea) {
      const Vec3f normal_l = area_light_normal(light);
      const double area = area_light_area(light);
      const int S = kAreaSpecularSamples, side = 4;  // a 4 x 4 jittered grid
      for (int j = 0; j < S; ++j) {
        const std::uint64_t k = mix(key + std::uint64_t(j) * 0x9E3779B97F4A7C15ull);
        const Vec3f p = area_light_point(light, (j % side + uniform01(k)) / side,
                                         (j / side + uniform01(k ^ 7)) / side);
        const Vec3f d = p - hit.x_o;
        const double r = d.norm();
        if (!(r > 0)) continue;
        const Vec3f w = d / float(r);
        const double cos_i = hit.n_o.dot(w), cos_p = -normal_l.dot(w);
        if (!(cos_i > 0) || !(cos_p > 0)) continue;
        const Vec3f offset = hit.g_o.dot(w) >= 0 ? hit.g_o : Vec3f(-hit.g_o);
        if (rays.occluded(hit.x_o + eps * offset, w, r - 2 * eps)) continue;
        sum += float(lobe(w, cos_i) * cos_p / (r * r) * area / S) * light.radiance;
      }
      continue;
    }
    Vec3f w;
    double scale = 1, distance = kInf;
    if (!toward_light(light, hit.x_o, w, scale, distance)) continue;
    const double cos_i = hit.n_o.dot(w);
    if (!(cos_i > 0)) continue;
    const Vec3f offset = hit.g_o.dot(w) >= 0 ? hit.g_o : Vec3f(-hit.g_o);
    if (rays.occluded(hit.x_o + eps * offset, w, distance - eps)) continue;
    sum += float(lobe(w, cos_i) * scale) * light.radiance;
  }
  return sum;
}

}  // namespace lucent::render::detail
