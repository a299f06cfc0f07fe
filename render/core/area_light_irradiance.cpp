// Area-light irradiance on the CPU (area_light_irradiance.h).
#include "area_light_irradiance.h"

#include <array>
#include <numbers>
#include <utility>
#include <vector>

namespace lucent::render::detail {

AreaIrradiance area_light_irradiance(const Light& light, const Vec3f& x, const Vec3f& n,
                                     const Vec3f& g, const RayScene* rays, float eps, double eta,
                                     const AreaLightSampling& sampling, std::uint64_t key) {
  AreaIrradiance out;
  std::array<Vec3d, kMaxPolygonVertices> vertices;
  const std::size_t count = light.polygon.size();
  for (std::size_t i = 0; i < count; ++i) vertices[i] = light.polygon[i].cast<double>();
  const Vec3d xd = x.cast<double>(), nd = n.cast<double>();
  const auto ff = polygon_form_factor<double>(
      xd, nd, std::span<const Vec3d>(vertices.data(), count));
  // One-sided emitter: a point behind the polygon's plane gets nothing (F <= 0 there).
  if (!(ff.F > 0)) return out;
  out.unshadowed = std::numbers::pi * ff.F;
  out.w = ff.vector.normalized().cast<float>();
  const int S = std::max(1, sampling.samples);
  const double area = area_light_area(light);
  const Vec3d normal_l = area_light_normal(light).cast<double>();
  // Latin-hypercube strata: s in stratum j, t in stratum perm(j), both jittered.
  std::array<int, 64> perm{};
  const int strata = std::min(S, 64);
  for (int j = 0; j < strata; ++j) perm[std::size_t(j)] = j;
  for (int j = strata - 1; j > 0; --j) {
    const int k = int(uniform01(key ^ (0x51ull + std::uint64_t(j))) * double(j + 1));
    std::swap(perm[std::size_t(j)], perm[std::size_t(std::min(k, j))]);
  }
  double sum = 0;
  for (int j = 0; j < S; ++j) {
    const std::uint64_t k = mix(key + 0x9E3779B97F4A7C15ull * std::uint64_t(j + 1));
    const int stratum = j % strata;
    const double s = (stratum + uniform01(k)) / strata;
    const double t = (perm[std::size_t(stratum)] + uniform01(k ^ 0xA5A5ull)) / strata;
    const Vec3f p = area_light_point(light, s, t);
    const Vec3d d = p.cast<double>() - xd;
    const double r2 = d.squaredNorm();
    if (!(r2 > 0)) continue;
    const double r = std::sqrt(r2);
    const Vec3d w = d / r;
    const double cos_x = nd.dot(w), cos_p = -normal_l.dot(w);
    if (!(cos_x > 0) || !(cos_p > 0)) continue;
    const double h = cos_x * cos_p / r2;
    bool visible = true;
    if (sampling.shadows && rays) {
      const Vec3f wf = w.cast<float>();
      const Vec3f offset = g.dot(wf) >= 0 ? g : Vec3f(-g);
      visible = !rays->occluded(x + eps * offset, wf, r - 2.0 * eps);
    }
    double f = visible ? materials::fresnel_transmittance(cos_x, eta) : 0.0;
    if (sampling.coat != nullptr) f *= sampling.coat->at(cos_x);
    sum += sampling.control_variate ? (f - 1.0) * h : f * h;
  }
  out.transmitted = area * sum / S + (sampling.control_variate ? out.unshadowed : 0.0);
  return out;
}

}  // namespace lucent::render::detail
