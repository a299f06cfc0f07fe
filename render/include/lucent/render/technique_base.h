// What every frame-by-frame technique is to its callers (the viewer, render_still's headless
// frames, the benchmarks): one lifecycle (setup, the scene's parts as they change, a frame, the
// image read back or presented) and its statistics in one form. The registry (technique.h) names
// the techniques and makes them; each technique's class (RadianceMapRenderer, ShRenderer,
// HierarchicalRenderer, FurRenderer) derives from `Technique` and keeps its own extras (the maps'
// snapshots, sh's debug outputs, fur's SH light) beside it.
//
// The CPU reference is not one: it renders stills (render_reference), which the viewer runs pass
// after pass on a worker thread.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "lucent/materials/material.h"
#include "lucent/render/scene.h"

namespace lucent::render {

enum class TechniqueId { kMaps, kSh, kHierarchical, kFur, kReference, kPathtrace };

struct TechniqueOptions;  // technique.h: every technique's options

/// A technique's last frame in numbers, the same form for all: the frames accumulated, its named
/// passes (wall clock, ms, in order) and a few lines of what it did (counts, the disc, the links).
struct FrameStats {
  int frames = 0;
  std::vector<std::pair<std::string, double>> pass_ms;
  std::vector<std::string> notes;

  /// "frames N; light map 1.20 ms, ...; NOTE; NOTE"
  std::string to_string() const;
};

/// The frame-by-frame lifecycle. Every call needs the same current OpenGL 4.5 core context (a
/// window's or GlContext::create_headless) and throws lucent::Error on what the context or the
/// technique cannot do. The setters take the scene's parts as they change; setting what a
/// technique already has changes nothing (no restart, no re-link).
class Technique {
 public:
  virtual ~Technique() = default;
  virtual TechniqueId id() const = 0;

  /// Uploads the mesh and builds programs and targets of the camera's size for `scene`, with its
  /// own part of `options` (validated).
  virtual void setup(const Scene& scene, const TechniqueOptions& options) = 0;
  /// The camera, of the size it was set up with unless the technique is resizable.
  virtual void set_camera(const Camera& camera) = 0;
  /// Whether set_camera takes another image size (else the caller sets the technique up anew).
  virtual bool resizable() const { return false; }
  virtual void set_lights(const std::vector<Light>& lights) = 0;
  virtual void set_material(const materials::Material& material) = 0;
  /// A deforming mesh: new positions (mm) and unit normals for the same vertices and triangles.
  virtual void set_geometry(const std::vector<Vec3f>& positions,
                            const std::vector<Vec3f>& normals) = 0;
  /// Discards what was accumulated (after a change the technique cannot see).
  virtual void restart() {}

  /// One frame. Returns false when it had nothing left to add (converged).
  virtual bool render_frame() = 0;
  /// True when further frames change nothing: a one-frame technique once it has drawn.
  virtual bool converged() const = 0;

  /// The last frame: linear RGB radiance, camera.width x camera.height, row 0 at the top.
  virtual ImageRgb read_image() const = 0;
  /// width * height: 1 where a pixel sees the object.
  virtual std::vector<std::uint8_t> read_mask() const = 0;
  /// The last frame tone-mapped (exposure, Reinhard, sRGB) into the bound draw framebuffer over
  /// the width x height pixels from (x, y) (GL's viewport: the lower left corner), stretched to
  /// them when the frame was rendered at another size (the viewer's reduced resolution).
  virtual void present(float exposure, int x, int y, int width, int height) const = 0;

  virtual FrameStats frame_stats() const = 0;
  std::string to_string() const { return frame_stats().to_string(); }
};

}  // namespace lucent::render
