// `--technique hierarchical` on OpenGL 4.5: the CPU solve of hierarchical.h each frame (links as
// its mode keeps them), the per-vertex B uploaded as a vertex attribute, and the fragment shader's
// (1 / pi) F_t(eta, n . w_o) B plus the lights' specular lobes
// (render/techniques/hierarchical/shaders/hierarchical.frag).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "lucent/render/hierarchical.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique_base.h"

namespace lucent::render {

/// Frame-by-frame renderer; needs a current OpenGL 4.5 core context for every call.
class HierarchicalRenderer final : public Technique {
 public:
  HierarchicalRenderer();
  ~HierarchicalRenderer() override;
  HierarchicalRenderer(const HierarchicalRenderer&) = delete;
  HierarchicalRenderer& operator=(const HierarchicalRenderer&) = delete;

  /// Builds the hierarchy, uploads the mesh, compiles the programs. Throws lucent::Error on bad
  /// options, an empty mesh, no light or more than 16 lights.
  void setup(const Scene& scene, const hierarchical::Options& options = {});
  /// The same with options.hierarchical.
  void setup(const Scene& scene, const TechniqueOptions& options) override;
  TechniqueId id() const override { return TechniqueId::kHierarchical; }
  void set_camera(const Camera& camera) override;  ///< same size as at setup
  void set_lights(const std::vector<Light>& lights) override;
  /// A material of other coefficients re-links (the links' cut-offs depend on them); the same
  /// coefficients again change nothing.
  void set_material(const materials::Material& material) override;
  void set_geometry(const std::vector<Vec3f>& positions,
                    const std::vector<Vec3f>& normals) override;

  /// One frame: the solve (hierarchical::Solver::solve), the upload, the draw.
  bool render_frame() override;  ///< always true

  ImageRgb read_image() const override;                  ///< linear RGB, row 0 at the top
  std::vector<std::uint8_t> read_mask() const override;  ///< 1 where a pixel sees the object
  void present(float exposure, int x, int y, int width, int height) const override;

  const hierarchical::Stats& stats() const;  ///< the solve's, last frame
  double upload_ms() const;         ///< last frame's B upload
  double draw_ms() const;           ///< last frame's draw (glFinish + wall clock)
  /// The last computation of the per-vertex single scattering (Scene::single_scattering), wall
  /// clock; 0 when off. Redone when the eye, lights, material or geometry change.
  double single_scattering_ms() const;
  const hierarchical::Solver& solver() const;

  /// The last frame's passes (the solve's stages, the upload, the draw) and its links.
  FrameStats frame_stats() const override;
  /// Every frame is the whole image: converged once one is drawn.
  bool converged() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One frame in a headless context of its own (fills `stats` when given: technique
/// "hierarchical", the phases' times, links and form-factor counts).
ImageRgb render_hierarchical(const Scene& scene, const hierarchical::Options& options,
                             RenderStats* stats = nullptr);

}  // namespace lucent::render
