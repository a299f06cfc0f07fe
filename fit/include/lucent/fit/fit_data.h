// What a fit consumes: radial bins (normal incidence) and/or 2D samples (oblique incidence) of pi L
// / P per mm^2, per channel, with standard errors, and the geometry they were taken in.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace lucent::fit {

struct RadialBins {
  std::vector<double> r_mm;        ///< representative radius (mean over the bin's pixels), mm
  std::vector<double> r_inner_mm;  ///< annulus, mm (equal to r_mm when only points are known)
  std::vector<double> r_outer_mm;
  std::array<std::vector<double>, 3> value;           ///< per mm^2 (or relative), per channel
  std::array<std::vector<double>, 3> standard_error;  ///< same units; > 0
  /// Side of the square pixels the bins were averaged from, mm; 0 when the bins are annuli of a
  /// continuous profile (Monte Carlo tallies, CSV). With pixels, a bin's value is the mean of pixel
  /// averages around r_mm, and the model is averaged over a pixel footprint at r_mm.
  double pixel_mm = 0;
  std::size_t size() const { return r_mm.size(); }
};

struct Samples2d {
  std::vector<double> x_mm, y_mm;  ///< from the entry point, surface coordinates, mm
  double pixel_mm = 0;             ///< footprint side, mm (0: points)
  std::array<std::vector<double>, 3> value;
  std::array<std::vector<double>, 3> standard_error;
  std::size_t size() const { return x_mm.size(); }
};

/// One measured profile (one capture).
struct ProfileData {
  std::string source;      ///< file it came from
  bool calibrated = true;  ///< false: values known up to one scale
  /// Relative standard error of the calibration (the beam power from the white reference), per
  /// channel; 0 when exact or unknown. The fit carries it as a per-channel scale with this prior,
  /// so that the reported uncertainties include it.
  std::array<double, 3> calibration_relative_se{};
  std::optional<double> eta;  ///< relative index when known (CSV: --ior)
  double incidence_polar_deg = 0;
  double incidence_azimuth_deg = 0;  ///< direction of travel from +x
  double view_deg = 0;
  /// Exitance (power per unit area, all directions: Monte Carlo tallies, CSV) rather than pi L
  /// along the view direction (a camera, or a CSV that says quantity=radiance).
  bool exitance = false;
  /// Values per unit power incident on the sample (a camera; lucent simulate's exitance CSV)
  /// rather than per unit power entering it (lucent profile's CSV, and CSV by default).
  bool per_incident_power = true;
  /// A slab's thickness, mm (absent: a semi-infinite sample), and the side the data are of: the
  /// lit one (reflectance) or the far one (transmittance).
  std::optional<double> thickness_mm;
  bool transmitted = false;
  /// The system response the white reference recorded (beam footprint, lens blur and glare, the
  /// pixel): radial, per mm^2, unit integral; and its rms radius, mm. Empty when not measured.
  std::vector<double> response_r_mm, response_value;
  double response_rms_mm = 0;
  /// Who recorded it, for the report ("the white reference recorded", "the beam image X recorded").
  std::string response_source = "the white reference recorded";
  RadialBins radial;
  std::optional<Samples2d> samples_2d;
  std::array<bool, 3> channels{true, true, true};  ///< which channels carry data
  std::vector<std::string> notes;  ///< what the reader assumed or skipped, for the report
};

/// Reads a `lucent-profile` JSON (from lucent acquire) or lucent's radial CSV: optional leading
/// `#` lines of `key=value` tokens (`ior=` or `eta=` the relative index, `quantity=exitance|
/// radiance`, `R_unit=..._per_unit_incident_power`, `incidence_deg=`, `view_deg=`, `pixel_mm=`,
/// `calibrated=true|false`, `calibration_relative_se=r,g,b`; what `lucent acquire`, `lucent
/// profile` and `lucent simulate --exitance-csv` write), the header `r_mm` and value columns `R` or
/// `R_r,R_g,R_b`, optional `se` / `se_r,se_g,se_b`, `r_inner_mm,r_outer_mm` (other columns, such as
/// acquire's pixel counts `n_r,n_g,n_b`, are ignored). CSV values are per
/// mm^2 per unit power entering unless the comments say otherwise; without se columns a 5%
/// relative error is assumed (a note says so); rows whose standard error is 0 (no Monte Carlo
/// photon arrived) are skipped and counted. Throws lucent::Error with one line naming the file,
/// line or field.
ProfileData load_profile_data(const std::filesystem::path& path);

/// The two readers load_profile_data chooses between, on bytes already read (the fuzz targets use
/// them); `source` names the file in errors.
ProfileData parse_profile_csv(std::string_view text, const std::string& source);
ProfileData profile_data_from_json(const nlohmann::json& doc, const std::string& source);

}  // namespace lucent::fit
