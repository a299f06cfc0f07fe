// Environment maps: a latitude-longitude (equirectangular) image of the radiance arriving from
// every direction, shown as the background and turned into a few directional lights by importance
// sampling its luminance (Dal Corso 2014 §4.4 and §5.5.3; docs/DESIGN.md §7.1 "Lights").
//
// Direction convention (y up, as the mesh and the orbit camera): pixel column u in [0, 1) runs over
// the azimuth phi = 2 pi u, pixel row v in [0, 1] (v = 0 the top row) over the polar angle
// theta = pi v measured from +y, and
//   direction(u, v) = (-sin theta sin phi, cos theta, sin theta cos phi),
// so the image centre (u = 0.5, v = 0.5) looks along -z, the way the default camera (azimuth 0, on
// +z) looks; u grows toward +x from there, so the background is not mirrored.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lucent/imaging/image.h"
#include "lucent/render/scene.h"

namespace lucent::render {

using Vec2f = Eigen::Vector2f;

/// Linear RGB radiance per direction, lat-long; relative units (the same as Light::radiance per
/// sr).
struct EnvironmentMap {
  imaging::ImageRgb image;
  std::filesystem::path source;

  std::string to_string() const;
};

/// The environment maps of the data package (scripts/install-deps: Poly Haven's CC0 HDRIs at
/// 512 x 256, from npm's @pmndrs/assets): their names, sorted (studio, sunset, forest, ...).
std::vector<std::string> environment_names();

/// A file path as given, or a bundled map's name (no folder, no extension) as its file in the data
/// cache; lucent::Error naming --env and listing the names otherwise.
std::filesystem::path resolve_environment(const std::string& name_or_path);

/// Reads `.exr` (OpenEXR, linear) or `.hdr` (Radiance RGBE) as a lat-long map. Anything else, a
/// file that is not an image, or an image with negative or non-finite values throws lucent::Error
/// naming the file.
EnvironmentMap load_environment(const std::filesystem::path& path);

/// Unit direction for lat-long coordinates (u, v) in [0, 1]^2 (see the convention above).
Vec3f latlong_direction(float u, float v);
/// Lat-long coordinates (u in [0, 1), v in [0, 1]) of a direction (need not be unit length).
Vec2f latlong_coordinates(const Vec3f& direction);

/// Radiance arriving from `direction` (bilinear, wrapping in u, clamped in v).
Vec3f environment_lookup(const EnvironmentMap& map, const Vec3f& direction);

/// Directions drawn in proportion to the map's luminance (Rec. 709) times each texel's solid angle
/// (integrated exactly over the texel's row), marginal over rows then conditional within the row,
/// uniform in solid angle within a texel; so the density per sr is the texel's luminance over the
/// map's integral of luminance. environment_lights draws its directions here, the path tracer its
/// next-event estimates of the environment.
class EnvironmentSampler {
 public:
  explicit EnvironmentSampler(const EnvironmentMap& map);

  bool black() const { return !(total_ > 0); }  ///< no light at all: nothing to sample
  /// The texel (i, j) and lat-long coordinates (u, v) for uniform numbers in [0, 1).
  void pick(double xi_row, double xi_col, int& i, int& j, float& u, float& v) const;
  /// A unit direction and its density per sr (0 only where black() is true).
  Vec3f sample(double xi_row, double xi_col, double& pdf_sr) const;
  /// The density per sr of drawing `direction` (need not be unit length).
  double pdf(const Vec3f& direction) const;
  double total() const { return total_; }  ///< the luminance integrated over the sphere

 private:
  const EnvironmentMap* map_;
  std::vector<double> band_;                  ///< cos theta_j - cos theta_{j+1} per row
  std::vector<std::vector<double>> row_cdf_;  ///< within each row
  std::vector<double> marginal_;              ///< over the rows
  double total_ = 0;
};

/// `count` directional lights that stand for the whole map: directions importance-sampled from the
/// luminance (Rec. 709) times each texel's solid angle (the sin(theta) correction of Dal Corso 2014
/// §4.4, integrated exactly over the texel's row), marginal over rows then conditional within the
/// row (Dal Corso 2014 §5.5.3), at the points of a 2D Halton sequence (bases 2, 3) shifted by a
/// random offset drawn from `seed` (Cranley-Patterson rotation: stratified, so a few lights are
/// stable). Within a texel the direction is uniform in solid angle. Each light's radiance is
/// L(direction) / (count * pdf(direction)), pdf over the sphere (per sr) = p(u, v) / (2 pi^2 sin
/// theta) in the limit of small texels, so that sum_k radiance_k f(direction_k) estimates the
/// integral of L f over the sphere for any f (a constant map of radiance 1 gives lights summing to
/// 4 pi). An all-black map gives no lights.
std::vector<Light> environment_lights(const EnvironmentMap& map, int count, std::uint64_t seed = 1);

}  // namespace lucent::render
