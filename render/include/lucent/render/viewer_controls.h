// What `lucent view` does with the mouse, the clock and the file system, kept apart from GLFW and
// Dear ImGui so that it can be tested without a window: the orbit camera, dragging a light around
// the object, the sine deformer (a mesh that changes every frame, to show that nothing is
// precomputed per mesh) and the material file watcher.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "lucent/render/scene.h"

namespace lucent::render {

/// The camera of `--view AZ,EL,DIST`, moved by the mouse: degrees, degrees, bounding-sphere radii.
struct OrbitView {
  float azimuth_deg = 30;
  float elevation_deg = 20;
  float distance_radii = 3.4f;

  static constexpr float kDegreesPerPixel = 0.4f;
  static constexpr float kMinDistance = 1.05f;  ///< just outside the bounding sphere
  static constexpr float kMaxDistance = 50;

  /// Left-button drag by (dx, dy) window pixels (y down, as GLFW reports them), as if grabbing the
  /// object: dragging right turns it right (the camera's azimuth falls), dragging down tips its top
  /// toward the viewer (the camera rises). Elevation stays within +-89 degrees, azimuth within
  /// [0, 360).
  void drag(float dx_px, float dy_px);
  /// Scroll wheel: each step up moves 10% closer; the distance stays in [kMinDistance, kMaxDistance].
  void zoom(float steps);
  Camera camera(const Mesh& mesh, int width, int height) const;
};

/// Turns a light about the mesh centre (the origin of a loaded mesh) by an azimuth about +y and an
/// elevation toward +y, both in degrees; elevation stays within +-89 degrees. Directional lights
/// turn their direction, point lights their position (its distance from the centre is kept).
/// Area lights turn rigidly with their centroid.
void drag_light(Light& light, float d_azimuth_deg, float d_elevation_deg);

/// Scales an area light's polygon about its centroid by `scale` (> 0; its radiance is kept, so its
/// power grows with its area); false (nothing changed) for other lights or a bad scale.
bool resize_light(Light& light, float scale);

/// The seeds' sine deformer along one axis: every vertex moves along x by
///   A sin(2 pi waves (y - y_min) / height + speed t),
/// A = amplitude * the rest mesh's bounding-box diagonal (mm), t in seconds; the normals are
/// recomputed (area-weighted) from the moved positions.
class SineDeformer {
 public:
  SineDeformer(Mesh rest, float amplitude, float waves = 1.0f, float speed_rad_per_s = 2.0f);
  /// The rest mesh moved to time t (s).
  void apply(double t_seconds, Mesh& out) const;
  const Mesh& rest() const { return rest_; }
  float amplitude_mm() const { return amplitude_mm_; }

 private:
  Mesh rest_;
  float amplitude_mm_, wavenumber_per_mm_, speed_, y_min_;
};

/// Watches a file by modification time and size (a material file that is being edited).
class FileWatcher {
 public:
  FileWatcher() = default;
  explicit FileWatcher(std::filesystem::path path);
  /// True once after the file changed since the last call (or since construction); false while it
  /// is missing or unchanged.
  bool changed();
  const std::filesystem::path& path() const { return path_; }

 private:
  struct Stamp {
    std::filesystem::file_time_type time;
    std::uintmax_t size = 0;
    bool operator==(const Stamp&) const = default;
  };
  std::optional<Stamp> stamp() const;
  std::filesystem::path path_;
  std::optional<Stamp> last_;
};

}  // namespace lucent::render
