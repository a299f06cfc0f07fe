// `--technique pathtrace`: the truth the previews are held to. Volumetric path tracing of the
// material's own medium (sigma_a, sigma_s, Henyey-Greenstein g per channel) inside the mesh, behind
// a smooth dielectric boundary of relative index eta (exact Fresnel reflection and refraction,
// total internal reflection included): no diffusion model, no BSSRDF. Lengths in mm, coefficients
// in mm^-1, radiance in the scene's relative units (W mm^-2 sr^-1 per unit light).
//
// How each light is reached (render/pathtrace/README in path_tracer.cpp's header comment):
// - eta = 1 (the boundary is invisible): next-event estimation from every collision straight to
//   every light, with the optical depth of the segments inside the mesh; the environment map and
//   area lights also by the phase function's sample escaping, the two combined by multiple
//   importance sampling (balance heuristic).
// - eta > 1: a directional or point light seen through a smooth refracting boundary is a caustic
//   (no straight shadow ray can reach it). Each collision connects to it through one refraction:
//   the boundary point whose refracted light ray passes through the collision (found by fixed-point
//   iteration along the refracted ray), weighted by the Fresnel transmittance and the beam's
//   change of cross-section (finite differences of the refracted rays, the boundary's interpolated
//   normals included): manifold next-event estimation with one refracting vertex. Light that
//   reaches a collision only after an internal reflection before its first scattering (the
//   unscattered beam crossing the object) is not connected; it is e^(-sigma_t chord) of the
//   entering light. Area lights use the same connection from a point drawn on the polygon, and
//   paths that reach them otherwise (after an internal reflection) are counted when they hit; the
//   environment is reached by the escaping paths.
// Unbiased otherwise: Russian roulette on the throughput, on next-event estimates deep inside
// (kept with probability e^(-(optical depth to the surface - 20)), weighted back), no cap on the
// number of collisions but a safety one (counted in the statistics).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"

namespace lucent::render {

struct PathTraceOptions {
  /// Paths per pixel per pass, each carrying the three channels (spectral MIS over their free
  /// paths). Noise falls as 1 / sqrt(samples); the statistics give the measured standard error.
  int pixel_samples = 64;
  int passes = 1;          ///< progressive: image = the mean over passes of new samples
  int threads = 0;         ///< worker threads; 0 = all hardware threads
  std::uint64_t seed = 1;  ///< same seed, same image, for any number of threads
  bool jitter = true;      ///< samples spread over the pixel (a box filter); false: its centre
  /// Collisions after which a path is ended (counted as truncated): a safety net, not a knob.
  int max_collisions = 1000000;
  float exposure = 1.0f;  ///< linear scale of the returned image
  /// Called now and then with the fraction done (0..1), from one thread at a time.
  std::function<void(double)> progress;

  void validate() const;  ///< throws lucent::Error naming the --pathtrace-* option
  std::string to_string() const;
};

struct PathTraceImage {
  ImageRgb image;                  ///< linear RGB radiance x exposure, mean over samples
  ImageRgb standard_error;         ///< per pixel and channel, of the mean (x exposure)
  std::vector<std::uint8_t> mask;  ///< 1 where the pixel's centre sees the object
  std::vector<ImageRgb> passes;    ///< the running mean after pass 1, 2, ...
  /// The object's mean per channel and its standard error (over the mask's pixels).
  std::array<double, 3> object_mean{}, object_mean_error{};
  RenderStats stats;  ///< phases, path counts (collisions, connections, truncated, leaks)
};

/// The scene's `specular` is the boundary's Fresnel reflection of what the camera sees (the
/// environment, the backdrop, the object itself; delta lights give no highlight on a smooth
/// surface); off, the camera sees only the light transmitted out of the medium (the internal
/// reflections stay: they are part of the transport). Renders scene.camera.width x
/// scene.camera.height pixels, row 0 at the top. The scene's environment map (if any) lights it
/// itself: the last scene.environment_lights of scene.lights, which stand for it in the other
/// techniques, are skipped. Throws lucent::Error on settings it cannot use.
PathTraceImage render_pathtrace(const Scene& scene, const PathTraceOptions& options = {});

}  // namespace lucent::render
