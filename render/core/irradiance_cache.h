// Jacob's storage of irradiance independent of the mesh (Jacob 1993, §2: "shadow maps" per face,
// here per cluster of faces): for static area lights, the transmitted irradiance E_t
// (area_light_irradiance.h) is stored on a regular grid in one projection plane per cluster of
// faces, and looked up bilinearly.
//
// - Clusters: faces grown over welded vertices (positions within 1e-5 of the object's size are
//   one vertex) while their normal stays within `max_normal_angle_deg` of the cluster's first face.
// - Projection: the plane perpendicular to the cluster's area-weighted normal; a grid of
//   `texel_mm` spacing over the cluster's projected bounds plus one texel of padding on every
//   side, so that every cell a face touches has its four corners.
// - Each grid vertex stands for a surface point: the face whose projection contains it (its
//   barycentric position and interpolated normal), or, for padding, the nearest face's plane
//   extrapolated; it is evaluated lazily, the first time a look-up needs it (once, thread-safe),
//   with the exact form factor and stratified shadow rays (the control variate of
//   area_light_irradiance.h).
// - Look-up: the point projected into its face's cluster, bilinear in the four corners.
// The error against direct evaluation is that of bilinear interpolation over a texel (and of
// evaluating padding off the surface): measured in tests/render/irradiance_cache_test.cpp.
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "area_light_irradiance.h"

namespace lucent::render::detail {

struct IrradianceCacheOptions {
  double max_normal_angle_deg = 30;  ///< cluster growth: normal within this of the first face's
  double texel_mm = 0;               ///< grid spacing; 0 = the bounding radius / 64
  int shadow_samples = 16;           ///< per grid vertex (area_light_irradiance)
  bool shadows = true;
  const FurCoat* coat = nullptr;     ///< a fur coat's transmittance (fur_coat.h), or none
};

struct IrradianceCacheStats {
  std::size_t clusters = 0;
  std::size_t grid_vertices = 0;     ///< allocated (covered or padding)
  std::size_t evaluated = 0;         ///< so far (lazily)
  double texel_mm = 0;
};

class IrradianceCache {
 public:
  using Rgb = std::array<double, 3>;

  /// The area lights of `lights` (others are ignored); `rays` (may be null: no shadows) must
  /// outlive the cache.
  IrradianceCache(const Mesh& mesh, const std::vector<Light>& lights, const RayScene* rays,
                  double eta, const IrradianceCacheOptions& options = {});
  ~IrradianceCache();

  /// E_t summed over the area lights, times their radiance (per channel), at point x (mm) of
  /// face `face`; and the E_t-weighted mean of their form-factor directions (unit, or zero).
  Rgb lookup(std::size_t face, const Vec3f& x, Vec3f* w = nullptr) const;

  /// Direct evaluation at the same point, for comparison (what the cache approximates).
  Rgb direct(std::size_t face, const Vec3f& x, Vec3f* w = nullptr) const;

  IrradianceCacheStats stats() const;

 private:
  struct Cluster;
  struct Vertex;
  void evaluate(Vertex& v) const;
  const Mesh& mesh_;
  std::vector<Light> lights_;  // the area lights
  const RayScene* rays_;
  double eta_;
  IrradianceCacheOptions options_;
  float eps_;
  std::vector<int> face_cluster_;
  std::vector<Cluster> clusters_;
  mutable std::atomic<std::size_t> evaluated_{0};
};

}  // namespace lucent::render::detail
