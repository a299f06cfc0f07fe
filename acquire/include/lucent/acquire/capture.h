// The capture file ("format": "lucent-capture", "version": 1; docs/DESIGN.md §3): what was
// photographed and how.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace lucent::acquire {

/// One exposure of a bracket.
struct Bracket {
  Bracket() = default;
  Bracket(std::filesystem::path p, double t = 0.0, std::optional<double> i = std::nullopt)
      : path(std::move(p)), exposure_s(t), iso(i) {}

  std::filesystem::path path;  ///< absolute, or relative to the capture file as written
  double exposure_s = 0.0;     ///< exposure time, s; 0: read from the camera RAW file's metadata
  std::optional<double> iso;   ///< ISO speed; absent: from a RAW file's metadata, or unknown
};

/// How code values map to linear light.
enum class Response { kLinear, kSrgb, kCalibrate };

/// A stack of brackets or one HDR image (exactly one of the two is set).
struct ImageSet {
  /// By strictly increasing exposure where the capture gives them (RAW files may leave them to
  /// their metadata: merge_brackets orders those).
  std::vector<Bracket> images;
  std::optional<std::filesystem::path> hdr;  ///< linear OpenEXR
};

struct WhiteReference {
  ImageSet images;
  double reflectance = 0.99;  ///< Lambertian reflectance of the reference (spectralon), in (0, 1]
};

struct Capture {
  static constexpr int kFormatVersion = 1;

  ImageSet sample;
  double pixel_pitch_mm = 0.0;         ///< size of one pixel on the sample, mm (> 0)
  double incidence_polar_deg = 0.0;    ///< beam angle from the normal, degrees, [0, 90)
  double incidence_azimuth_deg = 0.0;  ///< beam direction in the image plane from +x, degrees
  double view_deg = 0.0;               ///< camera angle from the normal, degrees, [0, 90)
  std::optional<double> ior;           ///< the sample's relative index, when known (fit uses it)
  /// A slab's thickness, mm, when the sample is one (absent: thick enough to count as
  /// semi-infinite), and which side the camera sees: the lit one (reflectance) or the far one
  /// (transmittance). lucent fit models the slab from these.
  std::optional<double> thickness_mm;
  bool transmitted = false;
  std::optional<std::array<double, 2>> beam_point_px;  ///< given entry point (x, y) in pixels
  Response response = Response::kLinear;
  std::optional<std::filesystem::path> dark;  ///< dark frame, same camera settings
  std::optional<WhiteReference> white_reference;
  std::optional<double> beam_power;  ///< in HDR radiance units x mm^2 sr (when no white reference)
  nlohmann::json provenance;         ///< free-form (the simulator records its settings here)

  /// Paths in the file are relative to this folder.
  std::filesystem::path base_dir;
};

std::string to_string(Response response);

/// Reads and validates a capture file; paths are resolved against the file's folder (existence is
/// checked when the images are read). Throws lucent::Error "<file>: field '<name>': <expected>".
Capture read_capture(const std::filesystem::path& path);

/// read_capture on a document already parsed; image paths are relative to `base_dir`.
Capture capture_from_json(const nlohmann::json& doc, const std::string& source,
                          const std::filesystem::path& base_dir);

/// The document for `capture` with paths as given (write them relative to the file's folder).
nlohmann::json capture_to_json(const Capture& capture);

/// Writes a capture file atomically.
void write_capture(const std::filesystem::path& path, const Capture& capture);

}  // namespace lucent::acquire
