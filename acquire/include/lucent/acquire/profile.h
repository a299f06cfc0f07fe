// The profile file ("format": "lucent-profile", "version": 1; docs/DESIGN.md §3): what `lucent
// acquire` measured around the beam entry point and what `lucent fit` reads. Radial bins always; 2D
// samples (one per pixel) for oblique incidence. Values are pi L / P per mm^2 (L the exit radiance,
// P the beam power) when calibrated, pi L in the capture's radiance units otherwise.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace lucent::acquire {

struct HdrResult;

/// Masked pixels of the whole sample image (not only those within the radius), per channel (R, G,
/// B), by reason.
struct MaskCounts {
  std::array<std::int64_t, 3> saturated{};  ///< saturated in every bracket (or no usable bracket)
  std::array<std::int64_t, 3> black{};  ///< code 0, or at/below the dark frame, in every bracket
  std::array<std::int64_t, 3> non_finite{};  ///< NaN or Inf in an HDR input
  std::int64_t total(int channel) const {
    return saturated[channel] + black[channel] + non_finite[channel];
  }
};

/// Radial bins around the entry point. Every vector has one entry per bin; per-channel vectors are
/// indexed [channel][bin].
struct RadialProfile {
  std::vector<double> r_mm;  ///< mean distance of the bin's pixel centres from the entry point, mm
  std::vector<double> r_inner_mm;  ///< bin edges, mm
  std::vector<double> r_outer_mm;
  std::array<std::vector<double>, 3> value;           ///< mean over the bin's unmasked pixels
  std::array<std::vector<double>, 3> standard_error;  ///< of that mean
  std::array<std::vector<std::int64_t>, 3> count;     ///< unmasked pixels in the bin
  std::size_t size() const { return r_mm.size(); }
};

/// One sample per unmasked pixel (unmasked in all three channels) within the radius.
struct Samples2d {
  std::vector<double> x_mm;  ///< pixel centre minus entry point along +x (image columns), mm
  std::vector<double> y_mm;  ///< along +y (image rows, downwards in the image), mm
  std::array<std::vector<double>, 3> value;
  std::array<std::vector<double>, 3> standard_error;
  std::size_t size() const { return x_mm.size(); }
};

struct Profile {
  static constexpr int kFormatVersion = 1;

  bool calibrated = false;  ///< values per mm^2 (pi L / P) when true, relative (pi L) when false
  std::string capture;      ///< the capture file, as given to `lucent acquire`
  double pixel_pitch_mm = 0;
  double incidence_polar_deg = 0;
  double incidence_azimuth_deg = 0;
  double view_deg = 0;
  std::optional<double> ior;  ///< the sample's relative index when the capture states it
  std::optional<double> thickness_mm;  ///< a slab's thickness, mm, when the capture states it
  bool transmitted = false;            ///< the far side of the slab (transmittance)
  /// The system response the white reference recorded (beam footprint, lens blur, glare, pixel):
  /// its radial profile about its own centre, per mm^2 with unit integral over the plane, and its
  /// rms radius (mm). Empty without a white reference.
  std::vector<double> response_r_mm, response_value;
  double response_rms_mm = 0;
  /// Entry point in pixels; pixel (i, j) covers [i, i + 1) x [j, j + 1), its centre is (i + 0.5, j
  /// + 0.5).
  std::array<double, 2> beam_point_px{};
  std::string beam_point_source = "detected";  ///< "detected" or "given"
  /// Beam power per channel, in the capture's radiance units x mm^2 x sr; absent when uncalibrated.
  std::optional<std::array<double, 3>> beam_power;
  RadialProfile radial;
  std::optional<Samples2d> samples_2d;  ///< oblique incidence only
  MaskCounts masked;
  nlohmann::json provenance = nlohmann::json::object();

  /// The "units" string written to the file.
  std::string units() const;
};

/// The document for `profile` ("format" and "version" included).
nlohmann::json profile_to_json(const Profile& profile);

/// Reads and validates a profile document; `source` names it in errors. Throws lucent::Error
/// "<source>: field '<name>': <expected>".
Profile profile_from_json(const nlohmann::json& doc, const std::string& source);

/// Reads a profile file (see profile_from_json).
Profile read_profile(const std::filesystem::path& path);

/// Writes the profile as JSON, atomically: "format" and "version" first, arrays of numbers on one
/// line.
void write_profile(const std::filesystem::path& path, const Profile& profile);

/// The radial bins as lucent's one radial CSV (what `lucent fit` reads): `#` lines of key=value
/// tokens (quantity, R_unit, calibrated, incidence_deg, view_deg, pixel_mm, ior, and the white
/// reference's calibration_relative_se), then r_mm,r_inner_mm,r_outer_mm,R_r,R_g,R_b,se_r,se_g,
/// se_b,n_r,n_g,n_b, one row per bin, numbers with 17 significant digits (lossless for doubles).
std::string profile_csv(const Profile& profile);

/// How pixels are grouped into radial bins.
struct RadialBinning {
  int bins = 150;  ///< number of bins (before dropping sparse ones)
  bool log_bins =
      false;  ///< log-spaced edges from pixel_pitch / 2 to the radius; first bin [0, pitch / 2)
  double radius_mm = 0;        ///< outer edge of the last bin, mm (> 0)
  int min_pixels_per_bin = 3;  ///< bins with fewer unmasked pixels in any channel are dropped
};

/// The bins + 1 edges in mm, increasing from 0 to binning.radius_mm. Throws lucent::Error when the
/// binning is unusable (no bins, radius not above pixel_pitch / 2 for log bins).
std::vector<double> radial_bin_edges_mm(const RadialBinning& binning, double pixel_pitch_mm);

/// Bins `hdr` around `beam_point_px`: per bin and channel the mean of scale[c] * radiance over the
/// unmasked pixels whose centres fall in [r_inner, r_outer) (the last bin includes its outer edge),
/// its standard error (the larger of the sample standard deviation / sqrt(n) and the propagated
/// per-pixel standard errors, so that a bin of identical values never claims zero error), the
/// count, and the mean r of the pixels. Bins with fewer than min_pixels_per_bin in any channel are
/// dropped.
RadialProfile bin_radial_profile(const HdrResult& hdr, const std::array<double, 2>& beam_point_px,
                                 double pixel_pitch_mm, const std::array<double, 3>& scale,
                                 const RadialBinning& binning);

/// Every pixel unmasked in all channels whose centre lies within radius_mm of the entry point.
Samples2d sample_2d_profile(const HdrResult& hdr, const std::array<double, 2>& beam_point_px,
                            double pixel_pitch_mm, const std::array<double, 3>& scale,
                            double radius_mm);

}  // namespace lucent::acquire
