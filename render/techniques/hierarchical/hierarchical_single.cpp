// The hierarchical technique's single-scattering term (hierarchical_single.h).
#include "hierarchical_single.h"

#include <algorithm>

#include "single_scattering.h"

namespace lucent::render::hierarchical {

std::vector<float> vertex_single_scattering(const detail::RayScene& rays, const Mesh& mesh,
                                            const materials::Material& material,
                                            const std::vector<Light>& lights, const Vec3f& eye,
                                            int threads) {
  const detail::SingleMedium medium = detail::SingleMedium::of(material);
  std::vector<detail::SingleLight> singles;
  for (const Light& light : lights) {
    if (light.type == LightType::kArea) continue;
    detail::SingleLight s;
    s.point = light.type == LightType::kPoint;
    s.toward =
        s.point ? light.position.cast<double>() : light.direction.normalized().cast<double>();
    s.radiance = light.radiance.cast<double>();
    singles.push_back(s);
  }
  const float scale = std::max(mesh.bounding_radius(), 1e-6f);
  const float epsilon = 1e-5f * scale;
  const auto entry = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& w,
                         const detail::SingleLight& light) {
    detail::LightEntry e;
    unsigned triangle = 0;
    float u = 0, v = 0, t = 0;
    const Vec3f origin = x.cast<float>(), direction = w.cast<float>();
    if (!rays.intersect_segment(origin, direction, epsilon, std::numeric_limits<float>::infinity(),
                                triangle, u, v, t)) {
      return e;  // x is outside
    }
    const auto& tri = mesh.triangles[triangle];
    const Vec3f n =
        ((1 - u - v) * mesh.normals[tri[0]] + u * mesh.normals[tri[1]] + v * mesh.normals[tri[2]])
            .normalized();
    // The light reaches the entry point unless the mesh is in the way (another part of it).
    const Vec3f exit = origin + t * direction;
    const double to_light = light.point ? (light.toward - exit.cast<double>()).norm()
                                        : std::numeric_limits<double>::infinity();
    if (rays.occluded(exit + 4 * epsilon * direction, direction, to_light)) return e;
    e.found = true;
    e.distance_mm = t;
    e.normal = n.cast<double>();
    return e;
  };
  std::vector<float> out(mesh.positions.size() * 3, 0.0f);
  detail::parallel_for(mesh.positions.size(), std::max(threads, 1), 64,
                       [&](std::size_t begin, std::size_t end) {
                         for (std::size_t i = begin; i < end; ++i) {
                           const Eigen::Vector3d x_o = mesh.positions[i].cast<double>();
                           const Eigen::Vector3d n_o = mesh.normals[i].cast<double>().normalized();
                           const Eigen::Vector3d w_o = (eye.cast<double>() - x_o).normalized();
                           Eigen::Vector3d L = Eigen::Vector3d::Zero();
                           for (const detail::SingleLight& light : singles) {
                             L += detail::single_scattering_radiance(
                                 medium, x_o, n_o, w_o, light, detail::kSingleScatteringSteps,
                                 [&](const Eigen::Vector3d& x, const Eigen::Vector3d& w) {
                                   return entry(x, w, light);
                                 });
                           }
                           for (int c = 0; c < 3; ++c) out[3 * i + std::size_t(c)] = float(L[c]);
                         }
                       });
  return out;
}

}  // namespace lucent::render::hierarchical
