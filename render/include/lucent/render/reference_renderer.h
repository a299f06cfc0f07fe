// The CPU reference (docs/DESIGN.md §7.5): the BSSRDF integrated over dense surface samples with
// shadow rays, the yardstick for every real-time technique's error. For each camera pixel that sees
// the object at x_o (normal n_o, toward the eye w_o):
//
//   L(x_o, w_o) = F_t(eta, n_o . w_o) sum_i (A / N) S_d(x_i, n_i, w_i, x_o, n_o) E_i,
//   E_i = radiance * max(0, n_i . w_i) * V(x_i, light) * F_t(eta, n_i . w_i)
//
// over N surface samples x_i drawn uniformly by area (A the mesh's area), per RGB channel with that
// channel's Medium; S_d is the model's BSSRDF without the Fresnel factors (dipole: R_d(|x_o - x_i|)
// / pi; ddipole: DirectionalDipole::S_d, w_i toward the light at x_i); point lights give intensity
// / distance^2. V is an Embree shadow ray.
//
// Two accelerations, both measured against brute force in tests/render/reference_renderer_test.cpp:
//  * A distance cutoff per channel: samples farther from x_o than r_cut (subsurface_cutoff_mm) are
//    skipped. r_cut is where, on a flat semi-infinite medium under uniform light, the exitance from
//    beyond r_cut is 1e-4 of the total; at most 1e-4 of any pixel on a flat surface.
//  * Hierarchical clusters (after Jensen and Buhler 2002, "A rapid hierarchical rendering technique
//    for translucent materials"): the samples' irradiance is summarised in a bounding-volume
//    hierarchy; a node whose bounding radius is below cluster_ratio times its distance from x_o
//    contributes through four sigma points per channel (its irradiance-weighted centroid offset by
//    +-sqrt(2 lambda_k) e_k along the two main axes of its irradiance-weighted covariance), which
//    reproduces the node's exact sum to second order in its size, instead of one evaluation per
//    sample (first order, Jensen and Buhler's centroid). The directional dipole also needs the
//    node's normals (and, for point lights, light directions) to agree: their mean has length >=
//    0.9 (0.99). cluster_ratio = 0 is brute force.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"

namespace lucent::render {

/// How the reference draws the points x_i it integrates over (--reference-sampling).
enum class ReferenceSampling {
  /// Probe rays importance-sampling the material's profile around each pixel (reference_probes.cpp,
  /// the default): pixel_samples per pixel per pass, noise independent of the mesh's area.
  kProbes,
  /// surface_samples uniform by area over the whole mesh, shared by every pixel, with clusters.
  kArea,
};
std::string to_string(ReferenceSampling sampling);  ///< probes | area

struct ReferenceOptions {
  ReferenceSampling sampling = ReferenceSampling::kProbes;
  /// kProbes: probes per pixel per pass. Noise falls as 1 / sqrt(samples); measured on this
  /// project's 2-core machine, 64 px marble sphere (directional + point light, ddipole): relative
  /// RMSE between two seeds 0.013 at 1024 (2.4 s), 0.009 at 2048 (4.9 s); dragon:4 0.024 at 1024.
  int pixel_samples = 1024;
  int surface_samples = 200000;  ///< kArea: N per pass, uniform by area, stratified over the area CDF
  int threads = 0;               ///< worker threads; 0 = all hardware threads
  std::uint64_t seed = 1;        ///< same seed, same image, for any number of threads
  int passes = 1;         ///< progressive: each pass draws N new samples; image = running mean
  bool shadows = true;    ///< shadow rays from each sample toward each light
  /// Area lights: points on the polygon (one shadow ray each) per surface point, stratified, and
  /// the analytic pi L F as a control variate (area_light_irradiance.h: unbiased either way; with
  /// it a fully visible light costs no noise). The kArea sampler always uses the plain mean.
  int area_light_samples = 4;
  /// Scene::single_scattering: collisions drawn on each pixel's refracted view ray per pass (the
  /// three channels together, reference_single.h); noise falls as 1 / sqrt of it.
  int single_samples = 16;
  bool area_light_control_variate = true;
  /// Area lights (kProbes): the irradiance from the per-cluster projection maps of Jacob 1993
  /// (render/core/irradiance_cache.h: exact form factor and `irradiance_cache_samples` shadow rays
  /// at grid vertices, bilinear between them) instead of shadow rays at every probe hit: faster,
  /// biased by the interpolation (measured in tests/render/irradiance_cache_test.cpp).
  bool irradiance_cache = false;
  double irradiance_cache_texel_mm = 0;  ///< 0: the bounding radius / 64
  int irradiance_cache_samples = 64;
  float exposure = 1.0f;  ///< linear scale of the returned images (1: radiance as computed)
  /// Hierarchical clustering: a node of bounding radius r at distance d is used as a whole when
  /// r < cluster_ratio * d. 0 = every sample evaluated (brute force: 5x slower at 20k samples,
  /// about 30x at 200k). Measured on a 100 mm marble sphere (directional dipole, 20k samples),
  /// RMS change against brute force over the object / its mean: 0.1: 2e-5, 0.2: 1e-4,
  /// 0.3: 4.5e-4, 0.5: 3.7e-3; the test holds the default below 2e-3.
  float cluster_ratio = 0.2f;
  /// Adds the Fresnel-reflected environment F_r(eta, n_o . w_o) L_env(reflect(-w_o, n_o)) when the
  /// scene has an environment map; off by default (the formula above has no specular term).
  bool environment_reflection = false;
  /// Called now and then with the fraction done (0..1), from one thread at a time.
  std::function<void(double)> progress;

  void validate() const;  ///< throws lucent::Error naming the option
  std::string to_string() const;
};

struct ReferenceImage {
  ImageRgb image;                  ///< linear RGB radiance x exposure, mean over the passes;
                                   ///< background: the environment map if any, else black
  std::vector<std::uint8_t> mask;  ///< width * height, 1 where the pixel sees the object
  std::vector<ImageRgb> passes;    ///< the running mean after pass 1, 2, ... (convergence)
  RenderStats stats;               ///< phases' wall-clock times, sample and evaluation counts
};

/// Renders scene.camera.width x scene.camera.height pixels, row 0 at the top. Throws lucent::Error
/// on settings it cannot use (no pixels, no samples, an empty mesh).
ReferenceImage render_reference(const Scene& scene, DiffusionModel model,
                                const ReferenceOptions& options = {});

/// Radius (mm) beyond which a channel's profile is skipped: on a flat semi-infinite medium lit
/// uniformly at normal incidence, the part of the exitance from sources farther than r_cut is at
/// most `tolerance` of the whole (numerical quadrature of the model's normal-incidence profile).
/// Infinite where the profile decays too slowly (no absorption).
double subsurface_cutoff_mm(const materials::Medium<double>& medium, DiffusionModel model,
                            double tolerance = 1e-4);

}  // namespace lucent::render
