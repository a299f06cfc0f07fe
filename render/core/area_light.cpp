// Polygonal area lights (render/core/area_light.h).
#include "area_light.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "lucent/core/error.h"

namespace lucent::render {

namespace {

Eigen::Vector3d area_vector(const std::vector<Vec3f>& p) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    sum += p[i].cast<double>().cross(p[(i + 1) % p.size()].cast<double>());
  }
  return 0.5 * sum;
}

}  // namespace

Light area_light(const std::vector<Vec3f>& polygon, const Vec3f& radiance,
                 const std::string& what) {
  const auto bad = [&](const std::string& why) { return Error(what + ": " + why); };
  if (polygon.size() < 3 || polygon.size() > std::size_t(kMaxPolygonVertices)) {
    throw bad("a polygon needs 3 to " + std::to_string(kMaxPolygonVertices) + " vertices, got " +
              std::to_string(polygon.size()));
  }
  for (const Vec3f& p : polygon) {
    if (!p.allFinite() || !(p.cwiseAbs().maxCoeff() <= 1e6f)) {
      throw bad("every vertex must be finite and within 1e6 mm of the mesh centre");
    }
  }
  if (!radiance.allFinite() || (radiance.array() < 0).any() || !(radiance.maxCoeff() <= 1e12f)) {
    throw bad("the radiance must be three numbers from 0 to 1e12");
  }
  double size = 0;
  for (const Vec3f& p : polygon) size = std::max(size, double((p - polygon[0]).norm()));
  const Eigen::Vector3d a = area_vector(polygon);
  // Zero area (collinear or repeated points) has no normal and emits nothing: refuse it rather
  // than render a light that is not there.
  if (!(a.norm() > 1e-10 * size * size) || !(size > 0)) {
    throw bad("the polygon has no area (its vertices are collinear or repeated)");
  }
  const Eigen::Vector3d n = a.normalized();
  const Eigen::Vector3d o = polygon[0].cast<double>();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d p = polygon[i].cast<double>();
    if (std::abs(n.dot(p - o)) > 1e-4 * size) {
      throw bad("the polygon must be planar (vertex " + std::to_string(i) + " is " +
                std::to_string(std::abs(n.dot(p - o))) + " mm off its plane)");
    }
    const Eigen::Vector3d q = polygon[(i + 1) % polygon.size()].cast<double>();
    const Eigen::Vector3d r = polygon[(i + 2) % polygon.size()].cast<double>();
    if (!(n.dot((q - p).cross(r - q)) > 0)) {
      throw bad("the polygon must be convex with distinct vertices (the turn at vertex " +
                std::to_string((i + 1) % polygon.size()) + " is not)");
    }
  }
  Light light;
  light.type = LightType::kArea;
  light.polygon = polygon;
  light.radiance = radiance;
  light.position = area_light_centroid(light);
  light.direction = area_light_normal(light);
  return light;
}

Light rect_light(const Vec3f& centre, const Vec3f& u, const Vec3f& v, const Vec3f& radiance,
                 const std::string& what) {
  if (!(u.cross(v).norm() > 1e-12f * std::max(u.squaredNorm(), v.squaredNorm())) ||
      !(u.norm() > 0) || !(v.norm() > 0)) {
    throw Error(what + ": the half-edge vectors U and V must be non-zero and not parallel");
  }
  return area_light({centre - u - v, centre + u - v, centre + u + v, centre - u + v}, radiance,
                    what);
}

std::vector<Light> triangle_lights(const std::vector<Vec3f>& positions,
                                   const std::vector<std::array<unsigned, 3>>& triangles,
                                   const Vec3f& radiance) {
  std::vector<Light> lights;
  lights.reserve(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    std::vector<Vec3f> polygon;
    for (unsigned i : triangles[t]) {
      if (i >= positions.size()) {
        throw Error("area light triangle " + std::to_string(t) + ": vertex index " +
                    std::to_string(i) + " out of range");
      }
      polygon.push_back(positions[i]);
    }
    lights.push_back(area_light(polygon, radiance, "area light triangle " + std::to_string(t)));
  }
  return lights;
}

Vec3f area_light_normal(const Light& light) {
  return area_vector(light.polygon).normalized().cast<float>();
}

double area_light_area(const Light& light) {
  return area_vector(light.polygon).norm();
}

Vec3f area_light_centroid(const Light& light) {
  const std::vector<Vec3f>& p = light.polygon;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0;
  for (std::size_t i = 1; i + 1 < p.size(); ++i) {
    const double a = (p[i] - p[0]).cast<double>().cross((p[i + 1] - p[0]).cast<double>()).norm();
    sum += a * (p[0] + p[i] + p[i + 1]).cast<double>() / 3.0;
    total += a;
  }
  return total > 0 ? Vec3f((sum / total).cast<float>()) : p.front();
}

Vec3f area_light_point(const Light& light, double s, double t) {
  const std::vector<Vec3f>& p = light.polygon;
  const std::size_t fans = p.size() - 2;
  // Fan triangles (p0, p_i, p_i+1) by their area; s is rescaled within the chosen one.
  std::array<double, kMaxPolygonVertices> cumulative{};
  double total = 0;
  for (std::size_t i = 0; i < fans; ++i) {
    total += (p[i + 1] - p[0]).cast<double>().cross((p[i + 2] - p[0]).cast<double>()).norm();
    cumulative[i] = total;
  }
  double target = std::clamp(s, 0.0, 1.0) * total;
  std::size_t i = 0;
  while (i + 1 < fans && target >= cumulative[i]) ++i;
  const double below = i == 0 ? 0.0 : cumulative[i - 1];
  const double width = cumulative[i] - below;
  const double u = width > 0 ? std::clamp((target - below) / width, 0.0, 1.0) : 0.5;
  // Uniform on the triangle: barycentrics (1 - sqrt u, sqrt u (1 - t), sqrt u t).
  const double su = std::sqrt(u), tt = std::clamp(t, 0.0, 1.0);
  const Eigen::Vector3d a = p[0].cast<double>(), b = p[i + 1].cast<double>(),
                        c = p[i + 2].cast<double>();
  return ((1 - su) * a + su * (1 - tt) * b + su * tt * c).cast<float>();
}

Light point_light_equivalent(const Light& light) {
  if (light.type != LightType::kArea) return light;
  Light point;
  point.type = LightType::kPoint;
  point.position = area_light_centroid(light);
  point.radiance = light.radiance * float(area_light_area(light));
  return point;
}

void transform_area_light(Light& light, const Vec3f& offset, float scale) {
  const Vec3f centre = area_light_centroid(light);
  for (Vec3f& v : light.polygon) v = centre + offset + scale * (v - centre);
  light.position = area_light_centroid(light);
}

}  // namespace lucent::render
