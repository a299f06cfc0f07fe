// `lucent acquire`: a capture (brackets or an HDR image, docs/DESIGN.md §2) -> calibrated HDR and
// profiles.
//
// Writes into one output folder, whole or not at all: capture.exr (linear float radiance, per
// second of exposure, dark subtracted; masked pixels 0), profile.json and profile.csv (profile.h)
// and acquire.png (the tone-mapped HDR with the entry point, rings at every 10th bin edge and
// masked pixels in magenta, for a person to check the detection).
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/acquire/beam.h"
#include "lucent/acquire/profile.h"

namespace lucent::acquire {

struct AcquireOptions {
  int bins = 150;         ///< radial bins from 0 to the radius (before dropping sparse ones)
  bool log_bins = false;  ///< log-spaced bins from pixel_pitch / 2 to the radius
  /// Outer radius of the bins and of the 2D samples, mm; default: the distance from the entry point
  /// to the nearest image edge.
  std::optional<double> radius_mm;
  int min_pixels_per_bin =
      3;  ///< bins with fewer unmasked pixels (in any channel) are dropped; >= 2
  BeamDetectionOptions beam;  ///< used unless the capture gives beam_point_px
  int ring_every_bins = 10;   ///< acquire.png draws a ring at every n-th bin edge
  /// Called as each stage starts, with its name and the share of the work done before it.
  std::function<void(const std::string& stage, double done)> progress;
};

struct AcquireSummary {
  std::array<double, 2> beam_point_px{};  ///< pixel-centre convention of beam.h
  std::string beam_point_source;          ///< "detected" or "given"
  bool calibrated = false;
  std::optional<std::array<double, 3>> beam_power;  ///< per channel (radiance units x mm^2 sr)
  std::string beam_power_source;                    ///< "white reference", "capture" or "none"
  MaskCounts masked;
  int width = 0, height = 0;  ///< pixels
  double radius_mm = 0;
  int bins_written = 0;                      ///< radial bins kept
  int samples_2d = 0;                        ///< 0 at normal incidence
  std::vector<std::filesystem::path> files;  ///< written, in the output folder
};

/// Runs the whole job; nothing is written unless everything succeeded. Throws lucent::Error with
/// one line naming the file, field or option on bad input.
AcquireSummary run_acquire(const std::filesystem::path& capture_json,
                           const std::filesystem::path& out_dir,
                           const AcquireOptions& options = {});

nlohmann::json summary_to_json(const AcquireSummary& summary);

/// A few lines for a person: entry point, beam power, masked pixels, files.
std::string to_string(const AcquireSummary& summary);

}  // namespace lucent::acquire
