// The directional-dipole radiance-map technique (Dal Corso 2014, Dal Corso 2014, chapters 4-5;
// DESIGN §7.1 and §7.2) on OpenGL 4.5: per frame,
//   1. light map: positions, normals and depth of the mesh seen from every light (one layer each;
//      orthographic fitted to the mesh for directional lights, perspective for point lights);
//   2. radiance maps: the mesh from K Halton directions into a K-layer array in one instanced draw;
//      every texel gathers its share of N of M exponentially biased disc samples around its point's
//      projection in each light map, rotated per texel and per frame, and adds the sum to the
//      previous frame's (ping-pong), up to T frames;
//   2b. alpha-weighted blur into mip levels through texture views, the level chosen from the frame
//      count;
//   3. final: each fragment averages the layers that see it (shadow-sampler depth test, shrink
//   along
//      the layer plane against seams), adds the Fresnel-reflected environment, and is read back
//      linear (or tone-mapped on screen by present()).
// Units: mm for lengths (the scene's), the lights' radiance units for the result. Deviations from
// the seed are documented where they are made (render/techniques/maps/radiance_maps_sampling.h, the
// shaders).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique_base.h"

namespace lucent::render {

/// The pipeline's own knobs beyond RenderSettings (K, N, M, q, T, W_s, W_l, model, exposure).
struct RadianceMapOptions {
  /// Blur levels at the first frame, fewer as frames accumulate (seed §6.2.4: two passes at the
  /// first frame, none at convergence); 0 = no blur; -1 (default): 0 with the profile disc, 2 with
  /// the seed's exponential one. Measured on dragon:4 (K 8, W 256, N 32, M 256, T 64), relative RMSE
  /// against the converged image at frames 1 / 4 / 16: blur 2 0.065 / 0.067 / 0.027, no blur
  /// 0.034 / 0.024 / 0.006: the profile disc's first frames are already smooth, and the blur only
  /// smears thin parts into their surroundings.
  int max_blur_level = -1;
  /// The final pass's mean over the layers that see x_o: weighted by cos_k = n_o . w_k, the
  /// layer's texel density on the surface (lucent's), or equal weights (Dal Corso 2014 §5.4.4;
  /// `--maps-layer-weights equal`, for the thesis's own configuration).
  bool cos_weighted_layers = true;
  /// Depth bias of the layer visibility test, in radiance-map texels of world size (seed §5.4.3).
  float shadow_bias_texels = 1.5f;
  /// Shrink of x_o along the layer plane against seams, in texels (seed §5.4.4: "one pixel").
  float shrink_texels = 1.0f;
  /// Seed 003 keeps one set of disc points and only rotates it per texel and per frame, so the
  /// accumulation converges to a fixed N-point quadrature in the radius. When set, every frame
  /// draws new radii too (the Halton disc shifted by a low-discrepancy offset per frame), and the
  /// accumulated estimate converges to the disc integral itself as frames add up (an extension).
  bool new_radii_each_frame = false;
  /// Convergence: the first frame whose image differs from the previous one by less than this
  /// relative RMS over object pixels (reported in the stats; rendering still runs to T frames).
  double convergence_tolerance = 0.01;
  /// glFinish and a wall clock around each stage (GL_TIME_ELAPSED queries are always recorded;
  /// llvmpipe under-reports them).
  bool time_stages = true;
  /// Add F_r(eta, n_o . w_o) L_env(reflect(-w_o, n_o)) where the scene has an environment map.
  bool environment_reflection = true;
  /// setup() only checks its inputs; prepare_step() then does the GL set-up a step at a time
  /// (under ~100 ms each on llvmpipe: the programs' first draws a step each), and the first
  /// render_frame() whatever is left.
  bool staged_setup = false;
  /// render_radiance_maps calls this with the image after each frame listed in `snapshot_frames`
  /// (`lucent render --snapshots`: convergence against frame count).
  std::function<void(int frame, const ImageRgb& image)> on_snapshot;
  std::vector<int> snapshot_frames;

  void validate() const;  ///< throws lucent::Error naming the option
  std::string to_string() const;
};

/// Per-stage times, ms.
/// The GPU memory the radiance maps allocate, MiB (2^20 bytes): the two K-layer RGBA32F radiance
/// arrays (ping-pong) with their mip levels, the shared K-layer 32-bit depth array, and the L light
/// maps (positions and normals RGBA32F, face normals RGBA16F, 32-bit depth). The final target and
/// the small buffers are left out, as Dal Corso's Table 5.1 leaves them.
struct MapsMemory {
  double radiance_mib = 0, radiance_depth_mib = 0, light_maps_mib = 0;
  double total_mib() const { return radiance_mib + radiance_depth_mib + light_maps_mib; }
};
/// `mip_levels`: the radiance arrays' levels (1 + the blur levels, radiance_map_levels()).
MapsMemory maps_memory(const RenderSettings& settings, int lights, int mip_levels);
/// The radiance arrays' mip levels for a blur up to `max_blur_level` (-1: the options' default
/// for the settings' disc, as the renderer resolves it).
int radiance_map_levels(const RenderSettings& settings, int max_blur_level);
/// Dal Corso's formula (seed 003, §5.3.8), MiB: 4 {[(4 + 4) 4/3 + 1] K W_s^2 + (3 + 3 + 1) L W_l^2}
/// bytes (RGB light maps, mips as a third); 193 MiB at K 16, W_s = W_l = 512, one light.
double seed_maps_memory_mib(int directions, int radiance_map_size, int lights, int light_map_size);

struct StageTimes {
  double light_map_ms = 0, radiance_map_ms = 0, mip_blur_ms = 0, final_ms = 0;
  double total_ms() const { return light_map_ms + radiance_map_ms + mip_blur_ms + final_ms; }
};

struct RadianceMapStats {
  std::string gl_renderer;           ///< GL_RENDERER | GL_VERSION
  int frames = 0;                    ///< frames accumulated (t)
  int frames_rendered = 0;           ///< render_frame() calls since the last restart
  int convergence_frame = 0;         ///< first frame changing the image by < tolerance; 0: not yet
  std::vector<double> frame_change;  ///< relative RMS change of the image at frames 2, 3, ...
  MapsMemory memory;                 ///< what the renderer allocated (maps_memory)
  double setup_ms = 0;               ///< programs, textures, mesh upload (wall clock)
  double depth_pass_ms = 0;          ///< of it, the depth pre-pass of the K layers
  /// Of it, the untimed warm-up: one layer's gather (a band's time times the bands) and one final
  /// pass; a first draw's compiling included, so upper bounds on what frames will take.
  double warm_up_layer_ms = 0, warm_up_final_ms = 0;
  StageTimes last_wall;              ///< the last frame, glFinish + wall clock
  StageTimes sum_wall, sum_gpu;      ///< over accumulating frames (sum_gpu: GL_TIME_ELAPSED)
  int light_map_renders = 0;         ///< the light map is rendered on restart only
  double uncovered_fraction = 0;     ///< object pixels no layer sees (black holes, seed Fig. 5.22)
  double sigma_star_per_mm = 0;      ///< disc bias sigma* = min sigma_tr / q
  double disc_radius_mm = 0;         ///< R the M points were drawn in
  double used_disc_radius_mm = 0;    ///< rho the N nearest points stand for
  int samples_per_light = 0;         ///< N / L

  /// Mean per accumulated frame (light map: per render of it).
  StageTimes mean_wall() const;
  StageTimes mean_gpu() const;
  std::string to_string() const;
};

/// Frame-by-frame renderer for `lucent view` and tests. Every call needs the same current
/// OpenGL 4.5 core context (GlContext::create_headless, or a window's); it throws lucent::Error on
/// anything the context cannot do and on settings it cannot use.
class RadianceMapRenderer final : public Technique {
 public:
  RadianceMapRenderer();
  ~RadianceMapRenderer() override;
  RadianceMapRenderer(const RadianceMapRenderer&) = delete;
  RadianceMapRenderer& operator=(const RadianceMapRenderer&) = delete;

  /// Uploads the mesh, builds programs and textures for `settings` (validated), starts
  /// accumulating.
  void setup(const Scene& scene, const RenderSettings& settings,
             const RadianceMapOptions& options = {});
  /// The same with options.settings and options.maps.
  void setup(const Scene& scene, const TechniqueOptions& options) override;
  TechniqueId id() const override { return TechniqueId::kMaps; }
  /// With RadianceMapOptions::staged_setup: the next step of the set-up; true once it is done
  /// (always true otherwise).
  bool prepare_step();
  bool prepared() const;

  /// The viewer's camera, of any size; the radiance maps do not depend on it, so accumulation
  /// goes on.
  void set_camera(const Camera& camera) override;
  bool resizable() const override { return true; }
  /// New lights (at most 16), or a new material: accumulation restarts.
  void set_lights(const std::vector<Light>& lights) override;
  void set_material(const materials::Material& material) override;
  /// A deforming mesh: new positions (mm) and unit normals for the same vertices and triangles.
  /// The layer and light cameras are refitted to the new bounds; accumulation restarts.
  void set_geometry(const std::vector<Vec3f>& positions,
                    const std::vector<Vec3f>& normals) override;
  /// Discards the accumulated frames (call after any change the renderer cannot see).
  void restart() override;

  /// One frame: light map (after a restart), radiance maps and blur while fewer than T frames are
  /// accumulated, then the final pass. Returns true if it accumulated a frame.
  bool render_frame() override;
  int accumulated_frames() const;
  bool converged() const override;  ///< T frames accumulated: further frames change nothing
  /// Splits each frame across calls of render_frame (the viewer's frame budget): every layer in
  /// `bands` bands of rows (1: whole layers), `units_per_call` layer-bands a call (0: the whole
  /// frame at once, the default). A call that does not finish the frame shows the last finished
  /// frame (its final pass drawn again only when the camera moved); the frame's image is the same
  /// as unsplit. Changing `bands` restarts the
  /// frame in progress.
  void set_split(int bands, int units_per_call);
  int last_call_units() const;     ///< layer-bands the last call rendered (0: none)
  bool frame_in_progress() const;  ///< a split frame has begun and not finished  ///< T frames
                                   ///< accumulated: further frames change nothing

  /// The last final pass: linear RGB radiance, camera.width x camera.height, row 0 at the top.
  ImageRgb read_image() const override;
  /// width * height: 1 where a pixel sees the object, 0 elsewhere (as ReferenceImage::mask).
  std::vector<std::uint8_t> read_mask() const override;
  /// Draws the last final image tone-mapped (exposure, Reinhard, sRGB) into the currently bound
  /// draw framebuffer over the width x height pixels from (x, y) (the window of `lucent view`).
  void present(float exposure, int x, int y, int width, int height) const override;

  const RadianceMapStats& stats() const;
  /// The last frame's passes (wall clock) and the disc it used.
  FrameStats frame_stats() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Renders `scene` with the radiance-map technique in a headless context of its own: T frames, then
/// the image: linear RGB radiance, camera.width x camera.height, row 0 at the top (exposure is the
/// writer's business). Fills `stats` (pass timings: per-frame means of light map, radiance map, mip
/// blur, final, plus the details of RadianceMapStats) when given.
ImageRgb render_radiance_maps(const Scene& scene, const RenderSettings& settings,
                              RenderStats* stats = nullptr);
ImageRgb render_radiance_maps(const Scene& scene, const RenderSettings& settings,
                              const RadianceMapOptions& options, RenderStats* stats,
                              RadianceMapStats* details = nullptr);

/// The same as the last RenderStats of render_radiance_maps: pass means and the details, for a
/// renderer that has run its frames.
void fill_render_stats(const RadianceMapRenderer& renderer, const Scene& scene,
                       const RenderSettings& settings, const RadianceMapOptions& options,
                       double total_ms, RenderStats& stats);

/// `lucent render`'s maps within a time budget per image (frame_budget.h): the first level of
/// `ladder` (the coarse image) and then, level after level, the highest one whose setup and frames
/// are predicted (from the frames measured so far) to fit what is left of `budget_s`, until the
/// last level (the requested settings) has been rendered or no higher level fits.
struct BudgetedMapsOptions {
  std::vector<RenderSettings> ladder;  ///< maps_quality_ladder(requested, fixed)
  double budget_s = 0;                 ///< per image, s; infinity: up to the requested settings
  /// Called with each level's image that a higher level will refine (the first is the coarse
  /// one); the last level's image is the result.
  std::function<void(const ImageRgb& image, int level)> on_image;
  /// The share of the planned work done and the seconds the plan still predicts.
  std::function<void(double fraction, double left_s)> progress;
};
struct BudgetedMaps {
  ImageRgb image;                     ///< the last level rendered
  int level = 0;                      ///< its index in the ladder
  std::vector<double> level_seconds;  ///< wall clock of each level run, in order
  std::vector<int> levels_run;        ///< their indices, those given up included
  std::vector<int> levels_given_up;   ///< the levels whose first measured frame said no
  double requested_frame_ms = 0;      ///< the cost model's prediction for a requested frame
};
BudgetedMaps render_radiance_maps_within_budget(const Scene& scene,
                                                const RadianceMapOptions& options,
                                                const BudgetedMapsOptions& budget,
                                                RenderStats* stats);

}  // namespace lucent::render
