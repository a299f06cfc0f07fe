// The spherical-harmonics fast translucency technique (`--technique sh`, Banterle & Chalmers:
// Banterle and Chalmers 2006) on OpenGL 4.5. Nothing is precomputed per mesh: every frame
//   1. the primary light's shadow map (distance along its rays, shadow_map_size^2) and one
//      depth-peeling pass for the second surface; a separable Gaussian blur of the first depth;
//   2. the external cube map (cube_map_size^2 per face): six orthographic cameras along the axes of
//      the mesh's bounding box scaled to a cube, each texel storing E F_t of the surface it sees;
//   3. its projection onto 9 SH coefficients per channel by a two-stage reduction in a compute
//      shader (the coefficients stay on the GPU);
//   4. the final pass: B = q^T M q at the exit of the refracted view ray from the box, times the
//      attenuation of eq. 12 in the thickness (render/techniques/sh/sh_translucency.h has
//      the math, its corrections of the seed and its guard; the shaders say the rest).
// Lights: every light adds to the cube map's irradiance; the thickness, the cube map's shadows
// and the primary light's specular shadow come from one light, the primary: the one bringing the
// most irradiance (luminance) to the mesh's centre. An environment map enters as its
// importance-sampled directional lights (Scene::lights) and as the reflected background.
// The technique is not physically based (eq. 12 is dimensionally mm^-2 times an irradiance): its
// images are compared with the reference after a best-fit scale (render/image_compare.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique_base.h"

namespace lucent::render {

/// How the final pass attenuates B with the thickness d (sh_translucency.h has the formulas).
enum class ShAttenuation {
  kSeed,        ///< eq. 12 as printed (with the d_eff guard): a(d)
  kNormalised,  ///< R_tot a(d) / a(0): a point the light sees shows (1 / pi) F_t R_tot B, the
                ///< colour of a lit semi-infinite slab (an extension)
  kSlab,        ///< R_tot A(d) / A(0), A eq. 12 integrated over the plane at d (falls as e^(-sigma_tr
                ///< d) / d rather than d^-3; an extension, lucent's default: see the measurements
                ///< in notebooks_data/bench/README.md)
};
ShAttenuation parse_sh_attenuation(const std::string& text);  ///< seed | normalised | slab
std::string to_string(ShAttenuation attenuation);

struct ShOptions {
  int shadow_map_size = 512;  ///< the seed's 512^2 (`--shadow-map`)
  int cube_map_size = 64;     ///< texels per cube face, the seed's 64^2 (`--cube-map`)
  /// sigma of the depth map's separable Gaussian blur, shadow-map texels; the kernel reaches
  /// 3 sigma. The seed blurs with an "8x8" filter: sigma 1.5 spans 9 taps. 0: no blur.
  float depth_blur_sigma_texels = 1.5f;
  /// Base depth bias of the shadow tests, shadow-map texels (grown with the slope in the shaders).
  float shadow_bias_texels = 2.0f;
  /// The attenuation in the thickness d (ShAttenuation). Eq. 12 as printed scales each channel by
  /// sigma_t'^2 at d = 0, so a material's colour follows sigma_t' rather than its albedo
  /// (measured on a side-lit skin1 sphere: the best-fit scales of R, G, B differ 17-fold).
  ShAttenuation attenuation = ShAttenuation::kSlab;
  /// F_t in the cube texels: lucent's exact unpolarised Fresnel (false) or the seed's Schlick.
  bool schlick = false;
  /// glFinish and a wall clock around each pass (GL_TIME_ELAPSED queries are always recorded;
  /// llvmpipe under-reports them).
  bool time_passes = true;

  /// Throws lucent::Error naming the option of the first bad value.
  void validate() const;
  std::string to_string() const;
};

/// Per-pass times of the last frame and means, ms.
struct ShPassTimes {
  double shadow_ms = 0, peel_ms = 0, blur_ms = 0, cube_ms = 0, project_ms = 0, final_ms = 0;
  double total_ms() const {
    return shadow_ms + peel_ms + blur_ms + cube_ms + project_ms + final_ms;
  }
};

struct ShStats {
  std::string gl_renderer;  ///< GL_RENDERER | GL_VERSION
  int frames = 0;
  int primary_light = 0;    ///< index in Scene::lights
  double setup_ms = 0;
  double shadow_texel_mm = 0;  ///< a shadow-map texel at the mesh's centre, mm
  ShPassTimes last_wall, sum_wall, sum_gpu;
  ShPassTimes mean_wall() const;
  ShPassTimes mean_gpu() const;
};

/// What the final pass writes: the image, or the thickness pass's values for tests and debugging
/// (r: thickness d, mm; g: 1 beyond the second depth; b: 1 lit by the primary light), or the
/// surface position (mm).
enum class ShOutput { kImage, kThickness, kPosition };

/// Frame-by-frame renderer; needs a current OpenGL 4.5 core context for every call.
class ShRenderer final : public Technique {
 public:
  ShRenderer();
  ~ShRenderer() override;
  ShRenderer(const ShRenderer&) = delete;
  ShRenderer& operator=(const ShRenderer&) = delete;

  /// Uploads the mesh, builds programs and textures. Throws lucent::Error on bad options, an
  /// empty mesh, no light or more than 16 lights.
  void setup(const Scene& scene, const ShOptions& options = {});
  /// The same with options.sh.
  void setup(const Scene& scene, const TechniqueOptions& options) override;
  TechniqueId id() const override { return TechniqueId::kSh; }
  void set_camera(const Camera& camera) override;
  void set_lights(const std::vector<Light>& lights) override;
  void set_material(const materials::Material& material) override;
  /// A deforming mesh: new positions (mm) and unit normals for the same vertices and triangles.
  void set_geometry(const std::vector<Vec3f>& positions,
                    const std::vector<Vec3f>& normals) override;
  void set_output(ShOutput output);

  /// One frame: every pass (nothing is kept between frames but the GL objects).
  bool render_frame() override;  ///< always true

  /// The last final pass: linear RGB, camera.width x camera.height, row 0 at the top.
  ImageRgb read_image() const override;
  /// 1 where a pixel sees the object.
  std::vector<std::uint8_t> read_mask() const override;
  /// The last projection, channel c's coefficient k at [c][k] (read back from the GPU for tests).
  std::array<std::array<float, 9>, 3> read_coefficients() const;
  /// The last cube map: 6 faces of cube_map_size^2 RGBA texels, face-major, rows from t = 0.
  std::vector<float> read_cube_map() const;
  /// The tone-mapped last image into the bound draw framebuffer (the viewer).
  void present(float exposure, int x, int y, int width, int height) const override;

  const ShStats& stats() const;

  /// The last frame's passes (wall clock) and its primary light.
  FrameStats frame_stats() const override;
  /// Every frame is the whole image: converged once one is drawn.
  bool converged() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The GPU projection alone (tests): `rgba` holds 6 faces of face_size^2 RGBA texels as
/// read_cube_map() returns them. Needs a current context.
std::array<std::array<float, 9>, 3> project_cube_map_on_gpu(const std::vector<float>& rgba,
                                                             int face_size);

/// Renders one frame of `scene` in a headless context of its own and returns the linear image.
/// Fills `stats` (technique "sh", per-pass times) when given.
ImageRgb render_sh(const Scene& scene, const ShOptions& options, RenderStats* stats = nullptr,
                   ShStats* details = nullptr);

}  // namespace lucent::render
