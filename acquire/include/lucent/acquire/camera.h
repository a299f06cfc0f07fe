// A camera model that turns a radiance image into exposure brackets (docs/DESIGN.md §5): exposure
// times, a response curve, shot and read noise, a black level, 8- or 16-bit quantisation and
// saturation.
#pragma once

#include <cstdint>
#include <vector>

#include "lucent/acquire/capture.h"
#include "lucent/imaging/camera_raw.h"
#include "lucent/imaging/image.h"

namespace lucent::acquire {

struct CameraOptions {
  /// Exposure times, s, strictly increasing.
  std::vector<double> exposures_s = {1.0 / 1000, 1.0 / 250, 1.0 / 60, 1.0 / 15, 1.0 / 4};
  /// Code-value encoding: kLinear or kSrgb (kCalibrate is a way to read, not a camera).
  Response response = Response::kSrgb;
  int bits = 16;               ///< 8 or 16 bits per channel
  double full_well_e = 40000;  ///< electrons at saturation
  double read_noise_e = 4;     ///< read noise, electrons rms
  double black_level_e =
      200;            ///< pedestal added to every pixel, electrons (what a dark frame removes)
  bool noise = true;  ///< shot (Poisson) and read (Gaussian) noise; off: exact expectation
  /// Electrons per (radiance x exposure time), radiance in the image's units, s: the scene's scale.
  /// 0 picks it so that the brightest pixel at the shortest exposure fills `auto_fill` of the well.
  double electrons_per_radiance_s = 0;
  double auto_fill = 0.5;
  /// Noise stream; each image gets its own stream derived from it. run_simulation sets it from the
  /// transport's seed (one --seed for everything) and records it in truth.json.
  std::uint64_t seed = 1;
};

/// Throws lucent::Error naming the CLI option (--full-well-e, --read-noise-e, --black-level-e,
/// --camera-scale, --exposures, --bits, --response) for a value no camera has, with its unit.
void validate_camera_options(const CameraOptions& options);

/// The electrons-per-(radiance s) factor `options` gives for an image whose brightest value is
/// `peak_radiance` (options.electrons_per_radiance_s when that is set).
double camera_scale(const CameraOptions& options, double peak_radiance);

/// One bracket: expected electrons = radiance * exposure_s * scale + black level; shot noise on the
/// signal, read noise on everything; clipped at 0 and the full well; encoded (linear or sRGB) and
/// quantised to the bit depth. `stream` distinguishes images drawn with the same seed.
imaging::RawImage expose(const imaging::ImageRgb& radiance, double exposure_s, double scale,
                         const CameraOptions& options, std::uint64_t stream);

/// The same camera as a Bayer sensor (RGGB, 16-bit, linear): photosite (2x + i, 2y + j) sees pixel
/// (x, y) of `radiance` through its colour filter, each with its own noise, so that a RAW reader's
/// 2 x 2 quads give back the image at its pixel pitch. The pedestal is rounded to a whole code (a
/// DNG's BlackLevel as LibRaw reads it); exposure_s and ISO 100 go into the mosaic's metadata.
imaging::BayerMosaic expose_mosaic(const imaging::ImageRgb& radiance, double exposure_s,
                                   double scale, const CameraOptions& options,
                                   std::uint64_t stream);

/// The sRGB transfer function and its inverse on [0, 1].
double srgb_encode(double linear);
double srgb_decode(double encoded);

}  // namespace lucent::acquire
