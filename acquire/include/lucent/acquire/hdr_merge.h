// Exposure brackets -> linear HDR radiance with a per-pixel standard error and a mask
// (docs/DESIGN.md §5).
//
// Each bracket k gives an estimate x_k = (f(v_k) - f(v_dark)) / t_k of the radiance from its code
// value v_k (f the response: linear, sRGB or recovered by Debevec's method; v_dark the dark frame's
// code, or none). The merge is their weighted mean with weights
//
//   w_k = h(v_k) / Var(x_k),
//
// the minimum-variance combination under the noise model below, tapered by h to exactly 0 at code 0
// and at codes >= max_value - 1 (saturation): h = 1 over the valid range, falling linearly to 0
// over the lowest 1% and the highest 2% of the codes (away from clipping, where the noise is not
// Gaussian and the response least trustworthy). A plain hat weight min(v, max - 1 - v) would throw
// away the bright codes, which carry the best signal-to-noise ratio.
//
// Noise model, in linear units of one bracket: Var(f(v_k)) = g * s_k + sigma_read^2 + q_k^2, with
// s_k = x * t_k the signal, g the shot-noise gain (1 / full well for a camera quantising
// electrons), sigma_read the read noise and q_k^2 = (f(v + 1/2) - f(v - 1/2))^2 / 12 the
// quantisation variance of code v_k. So Var(x_k) = (g x t_k + sigma_read^2 + q_k^2) / t_k^2: with
// shot noise alone the weight is proportional to t_k (the longest unsaturated exposure counts
// most), with read noise alone to t_k^2. g and sigma_read^2 are fitted per channel (non-negative
// weighted least squares) to the squared differences of consecutive usable brackets of the same
// pixel, after a first merge with w_k = h(v_k) t_k; with a dark frame its own read noise (the same
// sigma_read) enters too. With fewer than kMinNoisePairs pairs (one bracket, or an 'hdr' capture)
// the model is var(L) = a L + b, fitted to the spread of each pixel around the mean of its four
// neighbours: an over-estimate where the image curves strongly, an under-estimate where the noise
// is spatially correlated (demosaiced or denoised files).
//
// Response 'calibrate' recovers the curve with OpenCV's CalibrateDebevec and then merges as above
// with that curve, not with OpenCV's MergeDebevec, which averages the weights over the three
// channels (a pixel saturated in red only would keep its saturated red code), averages in the log
// domain (biased under noise), cannot subtract a dark frame before dividing by the exposure time,
// and gives no standard error.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lucent/acquire/capture.h"
#include "lucent/acquire/profile.h"
#include "lucent/imaging/image.h"

namespace lucent::acquire {

/// Why a pixel's channel carries no value.
enum class PixelMask : std::uint8_t {
  kValid = 0,
  kSaturated,  ///< code >= max_value - 1 in every bracket (or no bracket usable, longest saturated)
  kBlack,      ///< code 0, or at/below the dark frame, in every bracket (or no bracket usable)
  kNonFinite,  ///< NaN or Inf in an HDR input
};

/// Code value -> linear value, per channel, for one bit depth.
struct ResponseCurve {
  Response kind = Response::kLinear;
  int max_value = 0;                          ///< 255 or 65535
  std::array<std::vector<double>, 3> linear;  ///< [channel][code], max_value + 1 entries each
};

/// The linear or sRGB curve for codes 0..max_value with a per-channel black level (camera RAW;
/// 0 for PNG/TIFF): kLinear: (v - black) / (max - black); kSrgb: srgb_decode of the same.
ResponseCurve standard_response(Response kind, int max_value,
                                const std::array<double, 3>& black = {0.0, 0.0, 0.0});

/// Recovers the camera response from 8-bit brackets with OpenCV's CalibrateDebevec (up to an
/// arbitrary scale, shared by everything merged with it). Throws lucent::Error for 16-bit input or
/// a single bracket.
ResponseCurve calibrate_response(const ImageSet& brackets, const std::filesystem::path& base_dir);

/// The fitted noise model (see the file comment), per channel; "source" says how it was obtained.
struct NoiseModel {
  std::string source;            ///< "bracket pairs", "neighbours" or "none"
  std::array<double, 3> gain{};  ///< bracket pairs: g; neighbours: a (radiance units)
  std::array<double, 3>
      read_variance{};       ///< bracket pairs: sigma_read^2 (linear units); neighbours: b
  std::int64_t samples = 0;  ///< pairs or pixels the fit used
};

struct HdrResult {
  imaging::ImageRgb radiance;        ///< linear, per second of exposure; 0 where masked
  imaging::ImageRgb standard_error;  ///< of radiance, same units; 0 where masked
  std::vector<PixelMask> mask;  ///< per pixel and channel, indexed like imaging::ImageRgb::data
  MaskCounts counts;
  NoiseModel noise;
  std::optional<ResponseCurve> response;       ///< the curve used (absent for an 'hdr' input)
  std::vector<std::filesystem::path> sources;  ///< the files read, resolved
  /// Per bracket, in merge order: the exposure each was divided by, s (times ISO / 100 when
  /// iso_scaled); empty for an 'hdr' input.
  std::vector<double> exposure_s;
  bool iso_scaled = false;   ///< every bracket's ISO was known: radiance is per s at ISO 100
  bool camera_raw = false;   ///< the brackets were camera RAW files (black and white from them)
  std::string sources_text;  ///< the sample's files in one short phrase, for messages

  int width() const { return radiance.width; }
  int height() const { return radiance.height; }
  PixelMask mask_at(int x, int y, int c) const {
    return mask[(std::size_t(y) * radiance.width + x) * 3 + c];
  }
  bool valid(int x, int y, int c) const { return mask_at(x, y, c) == PixelMask::kValid; }
};

/// Fewer bracket pairs than this and the noise model falls back to neighbour differences.
inline constexpr std::int64_t kMinNoisePairs = 32;

/// Merges `set` (brackets, or reads its 'hdr' OpenEXR) into linear radiance. Paths are resolved
/// against `base_dir`; `dark` is a dark frame at the same settings (same size and bit depth as the
/// brackets; for an 'hdr' set, an OpenEXR in the same units), subtracted in linear units before the
/// division by the exposure time. `curve` overrides the response (kCalibrate needs it: the sample's
/// recovered curve, so that a white reference is merged on the same scale); without it kCalibrate
/// calibrates on `set` itself. Throws lucent::Error naming the file for a missing or unreadable
/// image, mismatched sizes or bit depths, and for a channel with no usable pixel ("all-saturated",
/// "all-black", "no finite pixels").
HdrResult merge_brackets(const ImageSet& set, Response response,
                         const std::optional<std::filesystem::path>& dark,
                         const std::filesystem::path& base_dir,
                         const std::optional<ResponseCurve>& curve = std::nullopt);

}  // namespace lucent::acquire
