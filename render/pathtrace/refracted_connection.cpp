// Next-event estimation through one smooth refracting boundary (path_walk.h: refracted_connection):
// a delta light (directional or point) reaches a collision x inside a medium of eta > 1 only along
// the refracted ray that passes through x. Its boundary point y is the fixed point of
//   y_{k+1} = the boundary hit from x backward along refract(light at y_k, n(y_k)),
// started at the straight line's hit (exact after one step on a plane; on a curved surface each
// step shrinks the error by about (1 - 1/eta) |x - y| / (radius of curvature)). The irradiance
// at x perpendicular to the refracted beam is the light's, times the Fresnel transmittance at y,
// times the ratio of the beam's cross-sections before y and at x: central differences of the
// refracted rays over a patch of the triangle around y, with the mesh's interpolated normals, so
// the focusing of a curved boundary is included (on a plane it is cos theta_i / cos theta_t).
#include "lucent/materials/fresnel.h"
#include "path_walk.h"

namespace lucent::render::pathtrace {
namespace {

constexpr int kMaxIterations = 40;
constexpr double kBarycentricStep = 1e-3;  // central differences: O(step^2) error, ~1e-6

// The unit direction from p toward the light and the distance to it (infinite for a directional
// light); false at the light itself.
bool toward_light(const Light& light, const Vec3d& p, Vec3d& w, double& distance) {
  if (light.type == LightType::kDirectional) {
    w = light.direction.cast<double>().normalized();
    distance = std::numeric_limits<double>::infinity();
    return true;
  }
  w = light.position.cast<double>() - p;
  distance = w.norm();
  if (!(distance > 0)) return false;
  w /= distance;
  return true;
}

// The light's ray refracted at barycentrics (b1, b2) of a triangle: the surface point, the
// direction toward the light, the distance to it, and the travel direction inside.
bool refracted_ray(const World& w, const Light& light, unsigned triangle, double b1, double b2,
                   Vec3d& p, Vec3d& to_light, double& distance, Vec3d& travel) {
  Vec3d n;
  w.boundary.at(triangle, b1, b2, p, n);
  if (!toward_light(light, p, to_light, distance) || !(to_light.dot(n) > 0)) return false;
  return refract(-to_light, n, w.eta, travel);
}

}  // namespace

Link refracted_connection(const World& w, const Light& light, const Vec3d& x, Connection& out) {
  const Boundary& boundary = w.boundary;
  Vec3d to_light, travel;
  double distance = 0;
  if (!toward_light(light, x, to_light, distance)) return Link::kNone;
  auto y = boundary.hit(x, to_light, distance);
  if (!y) return Link::kNone;  // a point light inside the medium: no boundary between
  const double tolerance = boundary.epsilon();
  bool converged = false;
  for (int k = 0; k < kMaxIterations && !converged; ++k) {
    if (!toward_light(light, y->x, to_light, distance)) return Link::kNone;
    if (!(to_light.dot(y->n) > 0) || !(to_light.dot(y->ng) > 0)) return Link::kNone;  // behind it
    if (!refract(-to_light, y->n, w.eta, travel)) return Link::kNone;
    auto next = boundary.hit(x, -travel);
    if (!next) return Link::kFailed;
    converged = (next->x - y->x).norm() < tolerance;
    y = next;
  }
  if (!converged) return Link::kFailed;

  // The beam at y and at x (x lies on the central ray: x = y + |x - y| travel).
  Vec3d p0, l0, t0;
  double d0 = 0;
  if (!refracted_ray(w, light, y->triangle, y->b1, y->b2, p0, l0, d0, t0)) return Link::kNone;
  if (boundary.occluded(boundary.offset(*y, l0), l0, d0)) return Link::kNone;
  std::array<Vec3d, 4> p, l, t, q;
  std::array<double, 4> d{};
  const double h = kBarycentricStep;
  const std::array<std::array<double, 2>, 4> steps{{{h, 0}, {-h, 0}, {0, h}, {0, -h}}};
  for (std::size_t k = 0; k < 4; ++k) {
    if (!refracted_ray(w, light, y->triangle, y->b1 + steps[k][0], y->b2 + steps[k][1], p[k], l[k],
                       d[k], t[k])) {
      return Link::kFailed;
    }
    // Where the neighbouring ray crosses the plane through x perpendicular to the central ray.
    const double along = t[k].dot(t0);
    if (!(along > 0)) return Link::kFailed;
    q[k] = p[k] + ((x - p[k]).dot(t0) / along) * t[k];
  }
  double before = std::abs((p[0] - p[1]).cross(p[2] - p[3]).dot(l0));  // flux ~ E x this
  if (light.type == LightType::kPoint) before /= d0 * d0;              // I x solid angle
  const double after = std::abs((q[0] - q[1]).cross(q[2] - q[3]).dot(t0));
  if (!(after > 0) || !std::isfinite(before / after)) return Link::kFailed;

  const double transmitted = 1 - materials::fresnel_reflectance(l0.dot(y->n), w.eta);
  out.irradiance = transmitted * before / after;
  out.travel = t0;
  out.distance = (x - p0).norm();
  out.exit = p0;
  return Link::kConnected;
}

}  // namespace lucent::render::pathtrace
