// `--technique fur --mesh tile` (Klotzli & Olano, Klotzli and Olano) on OpenGL 4.5: the fur tile of
// fur.h (hairs, cross-sections, transfer precomputed on the CPU at setup) drawn as stacked shells,
// the lights projected onto the 25 real SH each frame and the per-fragment 25-term dot product with
// the shell's transfer (7 RGBA layers per shell), shells alpha-blended back to front over the skin.
//
// Shading: the light reaching a voxel, integral L(w) T(w) dw = sum_i c_i t_i (the seed's lighting
// model: no hair BRDF), scattered isotropically by hairs of the material's reduced albedo:
// L_out = albedo / (4 pi) sum_i c_i t_i, clamped at 0 (the SH of a point or directional light
// rings). The skin under the fur: albedo / pi times the bottom shell's sum (the light reaching it).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "lucent/render/fur.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique_base.h"

namespace lucent::render {

/// The SH coefficients (per channel) of the lights as seen from `centre` (mm), in the tile's frame
/// (tile z = world +y, tile x = world +x, tile y = world -z): a directional light E Y_i(d), a point
/// light I / r^2 Y_i(w), an area light by 64 stratified points L cos_p dA / r^2 Y_i(w).
std::array<ShVector<double>, 3> fur_light_sh(const std::vector<Light>& lights, const Vec3f& centre);

/// The same in the frame whose axes are the rows of `to_local` (a rotation: tangent, bitangent,
/// normal), so that local z is the hairs' up: the light's SH turned into a vertex's frame. For
/// these lights the basis is evaluated at the turned directions: exactly the rotation of the
/// world-frame coefficients (sh_rotate), without its cost.
std::array<ShVector<double>, 3> fur_light_sh(const std::vector<Light>& lights, const Vec3f& centre,
                                             const Eigen::Matrix3d& to_local);

/// The tile-frame direction of a world direction (the tile's frame: x, -z, y).
Eigen::Vector3d tile_from_world(const Eigen::Vector3d& w);

/// The frame of a vertex with unit normal n for fur over a mesh (rows: tangent, bitangent, n): the
/// tangent along n x (world +y), or along world +x at the poles (|n . y| > 0.9999). The tile's
/// hairs are statistically isotropic in azimuth, so any continuous tangent serves; this one turns
/// only near the poles.
Eigen::Matrix3d fur_vertex_frame(const Vec3f& n);

class FurRenderer final : public Technique {
 public:
  FurRenderer();
  ~FurRenderer() override;
  FurRenderer(const FurRenderer&) = delete;
  FurRenderer& operator=(const FurRenderer&) = delete;

  /// Builds the tile (CPU, threads) and the GL objects; the scene's mesh must be `tile`.
  void setup(const Scene& scene, const fur::FurOptions& options);
  /// The same with options.fur.
  void setup(const Scene& scene, const TechniqueOptions& options) override;
  TechniqueId id() const override { return TechniqueId::kFur; }
  void set_camera(const Camera& camera) override;  ///< same size as at setup
  void set_lights(const std::vector<Light>& lights) override;
  /// The light as SH coefficients per channel in the tile's frame (the viewer's rotating lobe).
  void set_light_sh(const std::array<ShVector<double>, 3>& light);
  /// The tile has no mesh to deform: ignored (the viewer's deformer moves other techniques).
  void set_geometry(const std::vector<Vec3f>&, const std::vector<Vec3f>&) override {}
  /// The hairs' and the skin's albedo (the material's reduced albedo per channel).
  void set_material(const materials::Material& material) override;
  /// 1 where the shells or the skin cover a pixel (alpha > 0).
  std::vector<std::uint8_t> read_mask() const override;
  void present(float exposure, int x, int y, int width, int height) const override;
  bool render_frame() override;  ///< always true
  ImageRgb read_image() const override;
  double precompute_ms() const;  ///< the tile's hairs, cross-sections and transfer
  double draw_ms() const;        ///< the last frame (glFinish + wall clock)

  /// The last frame's draw and the tile's precomputation.
  FrameStats frame_stats() const override;
  /// Every frame is the whole image: converged once one is drawn.
  bool converged() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One frame in a headless context (stats: technique "fur", precompute and draw times). On the
/// tile, Klotzli & Olano; on any other mesh, the extension: `skin` (the radiance maps' settings)
/// renders the BSSRDF under the coat (scene.fur_coat, or the tile's own coat_transmittance), then
/// the shells are drawn over it (fur_mesh.cpp). `skin_renderer`, when given, renders the skin
/// instead (`lucent render --budget`: the maps within what is left of the budget).
using SkinRenderer = std::function<ImageRgb(const Scene& skin_scene)>;
ImageRgb render_fur(const Scene& scene, const fur::FurOptions& options,
                    RenderStats* stats = nullptr, const RenderSettings& skin = {},
                    const SkinRenderer& skin_renderer = {});

/// Fur shells over a mesh (the extension of Klotzli & Olano): `render_fur` for meshes other than
/// the tile. Shells at (s + 0.5) height_mm / shells along the vertex normals, the tile mapped by
/// its width tile_mm onto the surface by triplanar projection (weights |n_a|^4), the lights' SH
/// evaluated per vertex in fur_vertex_frame and interpolated, alpha-blended inner to outer over
/// the skin image, which the mesh's depth occludes. No mesh-scale shadows on the hairs (the skin
/// has them: it comes from the maps).
ImageRgb render_fur_mesh(const Scene& scene, const fur::FurOptions& options,
                         const RenderSettings& skin, RenderStats* stats = nullptr,
                         const SkinRenderer& skin_renderer = {});

}  // namespace lucent::render
