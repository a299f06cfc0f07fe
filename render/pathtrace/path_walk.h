// The path tracer's pieces (path_tracer.h says what it computes): the boundary and its normals,
// the lights as the walk sees them, one channel's random walk, and the connection through a
// refracting boundary (refracted_connection.cpp).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "lucent/materials/material.h"
#include "lucent/render/environment.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/scene.h"
#include "ray_scene.h"

namespace lucent::render::pathtrace {

using Vec3d = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

/// A stream of uniform numbers in [0, 1) (SplitMix64: a counter through a strong mixer, so a path's
/// numbers depend only on its key, never on the thread).
class Random {
 public:
  explicit Random(std::uint64_t key) : state_(detail::mix(key)) {}
  double uniform() { return double(detail::mix(state_++) >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

/// A point on the boundary: position, the interpolated (shading) normal and the face's normal,
/// both pointing out of the mesh, and where on which triangle.
struct SurfacePoint {
  Vec3d x, n, ng;
  unsigned triangle = 0;
  double b1 = 0, b2 = 0;  ///< barycentrics of vertices 1 and 2
  double t = 0;           ///< distance along the ray that found it, mm
};

/// The mesh as the walk sees it: rays against the boundary, normals, a small offset.
class Boundary {
 public:
  explicit Boundary(const Mesh& mesh);
  /// The nearest boundary point along the ray, or none.
  std::optional<SurfacePoint> hit(const Vec3d& origin, const Vec3d& direction,
                                  double t_max = std::numeric_limits<double>::infinity()) const;
  /// Position and outward shading normal at barycentrics (b1, b2) of a triangle (extrapolated
  /// linearly a little outside it, for finite differences).
  void at(unsigned triangle, double b1, double b2, Vec3d& x, Vec3d& n) const;
  bool occluded(const Vec3d& origin, const Vec3d& direction, double distance) const;
  /// A point moved off the surface to the side `direction` leaves toward.
  Vec3d offset(const SurfacePoint& p, const Vec3d& direction) const {
    return p.x + (direction.dot(p.ng) > 0 ? epsilon_ : -epsilon_) * p.ng;
  }
  double epsilon() const { return epsilon_; }
  /// Every vertex on the inner side of every face's plane: a ray leaving never comes back in
  /// (checked for meshes up to 5e7 face-vertex pairs; larger ones are taken as not convex).
  bool convex() const { return convex_; }

 private:
  const Mesh& mesh_;
  detail::RayScene rays_;
  double epsilon_;
  bool flip_;  ///< the mesh's winding points its face normals inward
  bool convex_ = false;
};

/// Henyey-Greenstein: density per sr of turning by cos_theta, and a sampled new direction.
struct Phase {
  double g = 0;
  double pdf(double cos_theta) const {
    if (std::abs(g) < 1e-4) return 1 / (4 * kPi);
    return materials::henyey_greenstein(g, cos_theta);
  }
  Vec3d sample(const Vec3d& direction, double xi1, double xi2) const;
};

using Rgb = Eigen::Array3d;

/// The medium's three channels. One path carries all three (their throughputs in an Rgb): free
/// paths are drawn from a mixture of the channels' exponentials (a channel picked in proportion to
/// its throughput), and each channel is weighed by its own density over the mixture's (spectral
/// MIS: bounded by 1 / the channel's share, so a strongly absorbing channel costs no outliers).
struct MediumRgb {
  Rgb sigma_t = Rgb::Zero(), sigma_s = Rgb::Zero();
  std::array<Phase, 3> phase;
  bool one_phase = true;  ///< the same g in every channel: a turn weighs 1

  Rgb phase_pdf(double cos_theta) const {
    if (one_phase) return Rgb::Constant(phase[0].pdf(cos_theta));
    return Rgb(phase[0].pdf(cos_theta), phase[1].pdf(cos_theta), phase[2].pdf(cos_theta));
  }
};

/// An emitter of the scene as the walk sees it: delta lights (directional, point), convex area
/// polygons (emitting one-sided), and the environment map (or the constant backdrop, which is not
/// a light: it is what the camera sees behind the object).
struct AreaEmitter {
  std::vector<Vec3d> polygon;
  Vec3d normal;             ///< the side it emits toward
  std::vector<double> cdf;  ///< fan triangles by area
  double area = 0;
  Vec3d radiance;
};

struct Lights {
  std::vector<Light> delta;  ///< directional and point
  std::vector<AreaEmitter> area;
  std::optional<EnvironmentMap> environment;
  std::unique_ptr<EnvironmentSampler> environment_sampler;
  Vec3d backdrop = Vec3d::Zero();

  /// The radiance a ray leaving the scene in `direction` sees (environment or backdrop).
  Rgb background(const Vec3d& direction) const;
};
Lights gather_lights(const Scene& scene);

/// The nearest area emitter the ray hits within t_max, with its distance; -1 if none.
int hit_area_emitter(const Lights& lights, const Vec3d& origin, const Vec3d& direction,
                     double t_max, double& t);

/// How a refracted connection ended (refracted_connection): kNone where no such path exists (the
/// light behind the surface, something in the way), kFailed where the iteration did not converge.
enum class Link { kConnected, kNone, kFailed };

/// Counts gathered per worker and summed.
struct WalkCounts {
  std::uint64_t paths = 0, collisions = 0, connections = 0, connection_failures = 0, truncated = 0,
                leaks = 0;
  void count(Link outcome) {
    if (outcome == Link::kConnected) ++connections;
    if (outcome == Link::kFailed) ++connection_failures;
  }
  void add(const WalkCounts& o) {
    paths += o.paths, collisions += o.collisions, connections += o.connections;
    connection_failures += o.connection_failures, truncated += o.truncated, leaks += o.leaks;
  }
};

/// Everything a path needs, shared read-only by the workers.
struct World {
  const Boundary& boundary;
  const Lights& lights;
  MediumRgb medium;
  double eta = 1;
  bool matched = true;  ///< eta == 1: the boundary is invisible
  const PathTraceOptions& options;
  bool specular = true;  ///< the camera's own reflection off the boundary (Scene::specular)
};

/// The radiance arriving at `eye` along `direction`, per channel: one path carrying the channels
/// where `carried` is 1 (0 elsewhere in the result).
Rgb trace_path(const World& world, const Vec3d& eye, const Vec3d& direction, const Rgb& carried,
               Random& random, WalkCounts& counts);

/// The channels that share a path. Spectral MIS weighs a channel by its density over the mixture's
/// at every collision; where the channels' sigma_t differ those ratios multiply up over a long
/// path: the log-weight's variance grows like N ln^2(sigma_t,a / sigma_t,b) over the N ~ 1 / (1 -
/// the lower albedo) collisions while both carry weight. Channels share a path where that is below
/// 2: potato (0.1) and skin1 (0.4-1.3) one path, the same noise as three for half the time; marble
/// (8-42) one path per channel (one path for all had 2.8 times the noise at 64 paths).
std::vector<Rgb> channel_groups(const MediumRgb& medium);

/// The light that reaches collision x (inside) from every light and leaves it along `toward` (unit:
/// the direction back along the path, toward the camera side), per channel, before the collision's
/// weight: the sum over lights of phase x arriving radiance (irradiance for delta lights) x
/// transmittance. eta = 1 straight, eta > 1 through one refraction. `share`: the channels' shares
/// of the phase sample at x (their throughputs, normalised), whose mixture density the MIS weights
/// use where the path's escaping rays also count the environment and area lights; null without
/// escapes (single scattering alone): each estimate is whole.
Rgb next_event(const World& world, const Vec3d& x, const Vec3d& toward, Random& random,
               WalkCounts& counts, const Rgb* share);

/// The single-scattering radiance leaving boundary point p toward w_o (unit, toward the eye), per
/// channel: one collision on the refracted view ray (drawn from the channels' mixture, none past
/// the far boundary) with its next-event estimate of every light, times the Fresnel transmittance
/// out and 1 / eta^2. Jensen et al. 2001's single-scattering term (their eq. 9), with the exact
/// refracted light path (the connection) in place of their planar approximation.
Rgb single_scattering(const World& world, const SurfacePoint& p, const Vec3d& w_o, Random& random,
                      WalkCounts& counts);

/// The medium's channels and its relative index; throws lucent::Error if the channels' indices
/// differ.
MediumRgb medium_of(const materials::Material& material, double& eta);

/// eta > 1: the boundary point y such that light from `light` refracted at y travels straight to
/// x; the light's perpendicular irradiance there times the Fresnel transmittance and the beam's
/// change of cross-section, the travel direction inside (unit, y -> x) and the distance |x - y|.
/// kNone where no such path exists (the light below the surface there, something in the way),
/// kFailed where the iteration did not converge (counted: light missed).
struct Connection {
  double irradiance = 0;  ///< perpendicular to the refracted beam at x, per unit light radiance
  Vec3d travel;           ///< unit, from y to x
  double distance = 0;    ///< mm
  Vec3d exit;             ///< y, where the light crosses the boundary, mm
};
Link refracted_connection(const World& world, const Light& light, const Vec3d& x, Connection& out);

/// Refraction of travel direction d at a surface of normal n (facing the side d comes from,
/// n . d < 0) with relative index eta_rel = n_transmitted / n_incident; false on total internal
/// reflection.
inline bool refract(const Vec3d& d, const Vec3d& n, double eta_rel, Vec3d& t) {
  const double cos_i = -n.dot(d);
  const double sin2_t = (1 - cos_i * cos_i) / (eta_rel * eta_rel);
  if (sin2_t >= 1) return false;
  const double cos_t = std::sqrt(1 - sin2_t);
  t = (d / eta_rel + (cos_i / eta_rel - cos_t) * n).normalized();
  return true;
}

inline Vec3d reflect(const Vec3d& d, const Vec3d& n) {
  return d - 2 * d.dot(n) * n;
}

}  // namespace lucent::render::pathtrace
