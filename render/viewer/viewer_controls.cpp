// The viewer's controls without a window (see viewer_controls.h).
#include "lucent/render/viewer_controls.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <system_error>
#include <utility>
#include "area_light.h"

namespace lucent::render {
namespace {

constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;
constexpr float kMaxElevation = 89;

}  // namespace

void OrbitView::drag(float dx_px, float dy_px) {
  azimuth_deg = std::fmod(azimuth_deg - kDegreesPerPixel * dx_px, 360.0f);
  if (azimuth_deg < 0) azimuth_deg += 360;
  elevation_deg =
      std::clamp(elevation_deg + kDegreesPerPixel * dy_px, -kMaxElevation, kMaxElevation);
}

void OrbitView::zoom(float steps) {
  distance_radii = std::clamp(distance_radii * std::pow(0.9f, steps), kMinDistance, kMaxDistance);
}

Camera OrbitView::camera(const Mesh& mesh, int width, int height) const {
  return orbit_camera(mesh, azimuth_deg, elevation_deg, distance_radii, width, height);
}

void drag_light(Light& light, float d_azimuth_deg, float d_elevation_deg) {
  if (light.type == LightType::kArea) {
    // The polygon turns rigidly with its centroid (so a lamp facing the object keeps facing it).
    Light centre;
    centre.type = LightType::kPoint;
    centre.position = area_light_centroid(light);
    drag_light(centre, d_azimuth_deg, d_elevation_deg);
    const Eigen::Quaternionf turn =
        Eigen::Quaternionf::FromTwoVectors(area_light_centroid(light), centre.position);
    for (Vec3f& p : light.polygon) p = turn * p;
    light.position = area_light_centroid(light);
    light.direction = area_light_normal(light);
    return;
  }
  Vec3f& v = light.type == LightType::kDirectional ? light.direction : light.position;
  const float length = v.norm();
  if (!(length > 0)) return;
  // Same angles as orbit_camera: azimuth about +y from +z, elevation out of the xz-plane.
  const Vec3f u = v / length;
  const float elevation = std::asin(std::clamp(u.y(), -1.0f, 1.0f)) / kDeg;
  const float azimuth = std::atan2(u.x(), u.z()) / kDeg;
  const float az = (azimuth + d_azimuth_deg) * kDeg;
  const float el = std::clamp(elevation + d_elevation_deg, -kMaxElevation, kMaxElevation) * kDeg;
  v = length * Vec3f(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
}

bool resize_light(Light& light, float scale) {
  if (light.type != LightType::kArea || !(scale > 0) || !std::isfinite(scale)) return false;
  transform_area_light(light, Vec3f::Zero(), scale);
  return true;
}

SineDeformer::SineDeformer(Mesh rest, float amplitude, float waves, float speed_rad_per_s)
    : rest_(std::move(rest)), speed_(speed_rad_per_s) {
  const Vec3f lo = rest_.bounds_min(), hi = rest_.bounds_max();
  amplitude_mm_ = amplitude * (hi - lo).norm();
  const float height = std::max(hi.y() - lo.y(), 1e-6f);
  wavenumber_per_mm_ = 2 * std::numbers::pi_v<float> * waves / height;
  y_min_ = lo.y();
}

void SineDeformer::apply(double t_seconds, Mesh& out) const {
  out.triangles = rest_.triangles;
  out.name = rest_.name;
  out.positions.resize(rest_.positions.size());
  const float phase = float(std::fmod(speed_ * t_seconds, 2 * std::numbers::pi));
  for (std::size_t i = 0; i < rest_.positions.size(); ++i) {
    Vec3f p = rest_.positions[i];
    p.x() += amplitude_mm_ * std::sin(wavenumber_per_mm_ * (p.y() - y_min_) + phase);
    out.positions[i] = p;
  }
  out.normals = area_weighted_normals(out);
}

FileWatcher::FileWatcher(std::filesystem::path path) : path_(std::move(path)), last_(stamp()) {}

std::optional<FileWatcher::Stamp> FileWatcher::stamp() const {
  std::error_code error;
  const auto time = std::filesystem::last_write_time(path_, error);
  if (error) return std::nullopt;
  const auto size = std::filesystem::file_size(path_, error);
  if (error) return std::nullopt;
  return Stamp{time, size};
}

bool FileWatcher::changed() {
  if (path_.empty()) return false;
  const std::optional<Stamp> now = stamp();
  if (!now) return false;  // missing (an editor may be replacing it): wait for it to come back
  if (last_ && *now == *last_) return false;
  last_ = now;
  return true;
}

}  // namespace lucent::render
