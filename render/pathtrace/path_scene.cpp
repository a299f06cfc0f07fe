// The path tracer's view of the scene (path_walk.h): the boundary with its normals, the lights,
// the phase function's sampling.
#include <algorithm>

#include "lucent/core/error.h"
#include "path_walk.h"

namespace lucent::render::pathtrace {

Boundary::Boundary(const Mesh& mesh) : mesh_(mesh), rays_(mesh) {
  // Float vertices hold ~1e-7 of the object's extent: an offset of 1e-5 of it clears the surface
  // and is far below any mean free path the materials have (>= 1e-3 mm).
  epsilon_ = 1e-5 * (double(mesh.bounding_radius()) + double(mesh.centre().norm()));
  // Which way do the faces wind? Outward is where the vertex normals point.
  double agree = 0;
  for (const auto& tri : mesh.triangles) {
    const Vec3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                           .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    agree += double(face.dot(mesh.normals[tri[0]] + mesh.normals[tri[1]] + mesh.normals[tri[2]]));
  }
  flip_ = agree < 0;
  const double faces = double(mesh.triangles.size()), vertices = double(mesh.positions.size());
  if (faces * vertices <= 5e7) {
    const double tolerance = 1e-6 * (double(mesh.bounding_radius()) + 1e-9);
    convex_ = true;
    for (std::size_t t = 0; t < mesh.triangles.size() && convex_; ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3d a = mesh.positions[tri[0]].cast<double>();
      Vec3d n = (mesh.positions[tri[1]].cast<double>() - a)
                    .cross(mesh.positions[tri[2]].cast<double>() - a);
      if (!(n.norm() > 0)) continue;
      n.normalize();
      if (flip_) n = -n;
      for (const Vec3f& v : mesh.positions) {
        if ((v.cast<double>() - a).dot(n) > tolerance) {
          convex_ = false;
          break;
        }
      }
    }
  }
}

void Boundary::at(unsigned triangle, double b1, double b2, Vec3d& x, Vec3d& n) const {
  const auto& tri = mesh_.triangles[triangle];
  const double b0 = 1 - b1 - b2;
  x = b0 * mesh_.positions[tri[0]].cast<double>() + b1 * mesh_.positions[tri[1]].cast<double>() +
      b2 * mesh_.positions[tri[2]].cast<double>();
  n = (b0 * mesh_.normals[tri[0]].cast<double>() + b1 * mesh_.normals[tri[1]].cast<double>() +
       b2 * mesh_.normals[tri[2]].cast<double>())
          .normalized();
}

std::optional<SurfacePoint> Boundary::hit(const Vec3d& origin, const Vec3d& direction,
                                          double t_max) const {
  unsigned triangle = 0;
  float u = 0, v = 0, t = 0;
  if (!rays_.intersect_segment(
          origin.cast<float>(), direction.cast<float>(), 0.0f,
          std::isinf(t_max) ? std::numeric_limits<float>::infinity() : float(t_max), triangle, u, v,
          t)) {
    return std::nullopt;
  }
  SurfacePoint p;
  p.triangle = triangle;
  p.b1 = u, p.b2 = v;
  at(triangle, u, v, p.x, p.n);
  const auto& tri = mesh_.triangles[triangle];
  const Vec3d a = mesh_.positions[tri[0]].cast<double>();
  p.ng = (mesh_.positions[tri[1]].cast<double>() - a)
             .cross(mesh_.positions[tri[2]].cast<double>() - a)
             .normalized();
  if (flip_) p.ng = -p.ng;
  if (!p.n.allFinite()) p.n = p.ng;
  p.t = (p.x - origin).dot(direction);
  return p;
}

bool Boundary::occluded(const Vec3d& origin, const Vec3d& direction, double distance) const {
  return rays_.occluded(origin.cast<float>(), direction.cast<float>(), distance);
}

Vec3d Phase::sample(const Vec3d& direction, double xi1, double xi2) const {
  double cos_theta;
  if (std::abs(g) < 1e-4) {
    cos_theta = 1 - 2 * xi1;
  } else {
    const double s = (1 - g * g) / (1 - g + 2 * g * xi1);
    cos_theta = std::clamp((1 + g * g - s * s) / (2 * g), -1.0, 1.0);
  }
  const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  const double phi = 2 * kPi * xi2;
  // An orthonormal frame around `direction` (Duff et al. 2017).
  const Vec3d& w = direction;
  const double sign = std::copysign(1.0, w.z());
  const double a = -1 / (sign + w.z()), b = w.x() * w.y() * a;
  const Vec3d t1(1 + sign * w.x() * w.x() * a, sign * b, -sign * w.x());
  const Vec3d t2(b, sign + w.y() * w.y() * a, -w.y());
  return (sin_theta * std::cos(phi) * t1 + sin_theta * std::sin(phi) * t2 + cos_theta * w)
      .normalized();
}

Rgb Lights::background(const Vec3d& direction) const {
  if (environment)
    return environment_lookup(*environment, direction.cast<float>()).cast<double>().array();
  return backdrop.array();
}

Lights gather_lights(const Scene& scene) {
  Lights lights;
  const std::size_t own =
      scene.lights.size() - std::min(scene.lights.size(), std::size_t(scene.environment_lights));
  for (std::size_t k = 0; k < own; ++k) {
    const Light& light = scene.lights[k];
    if (light.type != LightType::kArea) {
      lights.delta.push_back(light);
      continue;
    }
    AreaEmitter e;
    for (const Vec3f& p : light.polygon) e.polygon.push_back(p.cast<double>());
    if (e.polygon.size() < 3) throw Error("--light: an area light needs 3 or more vertices");
    e.normal = (e.polygon[1] - e.polygon[0]).cross(e.polygon[2] - e.polygon[0]).normalized();
    e.cdf.push_back(0);
    for (std::size_t i = 1; i + 1 < e.polygon.size(); ++i) {
      e.area += 0.5 * (e.polygon[i] - e.polygon[0]).cross(e.polygon[i + 1] - e.polygon[0]).norm();
      e.cdf.push_back(e.area);
    }
    e.radiance = light.radiance.cast<double>();
    if (e.area > 0) lights.area.push_back(std::move(e));
  }
  if (scene.environment) {
    lights.environment = load_environment(*scene.environment);
    lights.environment_sampler = std::make_unique<EnvironmentSampler>(*lights.environment);
  }
  lights.backdrop = scene.backdrop.cast<double>();
  return lights;
}

int hit_area_emitter(const Lights& lights, const Vec3d& origin, const Vec3d& direction,
                     double t_max, double& t) {
  int found = -1;
  t = t_max;
  for (std::size_t k = 0; k < lights.area.size(); ++k) {
    const AreaEmitter& e = lights.area[k];
    const double facing = direction.dot(e.normal);
    if (!(facing < 0)) continue;  // one-sided: seen only from the side it emits toward
    const double tk = (e.polygon[0] - origin).dot(e.normal) / facing;
    if (!(tk > 0 && tk < t)) continue;
    const Vec3d p = origin + tk * direction;
    bool inside = true;  // convex: on the inner side of every edge
    for (std::size_t i = 0; i < e.polygon.size() && inside; ++i) {
      const Vec3d& a = e.polygon[i];
      const Vec3d& b = e.polygon[(i + 1) % e.polygon.size()];
      inside = (b - a).cross(p - a).dot(e.normal) >= 0;
    }
    if (inside) found = int(k), t = tk;
  }
  return found;
}

}  // namespace lucent::render::pathtrace
