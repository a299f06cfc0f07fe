// `lucent simulate`: a virtual capture rig. Monte Carlo transport (photon_transport.h) gives the
// exit radiance toward the camera; the camera model (camera.h) turns it into brackets, with a white
// reference and a dark frame, and a capture file that `lucent acquire` reads.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "lucent/acquire/camera.h"
#include "lucent/acquire/photon_transport.h"
#include "lucent/materials/material.h"

namespace lucent::acquire {

/// Where the exit radiance comes from.
enum class RadianceSource {
  kMonteCarlo,  ///< photon transport (the ground truth)
  kDipole,      ///< the standard dipole: F_t(in) R_d(r) F_t(out) / pi, for round trips of the fit
  kDirectionalDipole,  ///< the directional dipole: F_t(in) S_d F_t(out)
};

/// How the brackets are written: PNG (the camera's encoding, 8 or 16 bits), or DNG (a Bayer
/// sensor's linear 16-bit codes with black level, exposure time and ISO in the file; the capture
/// file then leaves exposure_s to the metadata).
enum class BracketFormat { kPng, kDng };

struct SimulateOptions {
  materials::Material material;
  RadianceSource source = RadianceSource::kMonteCarlo;
  PhotonTransportOptions transport;  ///< media are filled from `material`
  CameraOptions camera;
  bool white_reference = true;  ///< image a Lambertian reference of reflectance 0.99
  double white_reflectance = 0.99;
  /// Beam radius (1/e^2 half width / 2, i.e. the Gaussian sigma) on the white reference, mm; the
  /// pencil beam of the sample simulation is idealised, a reference spot needs some width to be
  /// imaged. 0 = one pixel pitch, or the beam's own sigma when it has one (transport.beam_sigma_mm:
  /// the same beam lights the reference).
  double white_spot_sigma_mm = 0;
  /// The lens: a Gaussian blur of this sigma (mm on the sample), and veiling glare, the fraction
  /// `glare` of every pixel's light spread over the field by the kernel a / (2 pi (r^2 + a^2)^1.5)
  /// (a = glare_radius_mm; unit integral, tails as 1 / r^3). Both act on the sample's and the
  /// white reference's images alike (and not on truth_radiance.exr, the light leaving the sample).
  double lens_blur_mm = 0;
  double glare = 0;
  double glare_radius_mm = 1;
  bool dark_frame = true;
  BracketFormat bracket_format = BracketFormat::kPng;
  bool profile_only = false;  ///< skip the images (transport without camera)
  std::optional<std::filesystem::path> exitance_csv;  ///< also write the radial table here
};

struct SimulateSummary {
  PhotonTransportResult transport;
  double camera_scale = 0;         ///< electrons per (radiance x s)
  std::vector<std::string> files;  ///< written, relative to the output folder
};

/// Runs the rig and writes into `out_dir` (atomically, as a whole folder): capture.json, bracket
/// PNGs, white-reference PNGs, dark.png, truth.json (the material and every setting), and
/// truth_radiance.exr / truth_radiance_se.exr (the exit radiance per unit power and its standard
/// error, mm^-2 sr^-1) — or only truth.json with `profile_only`.
SimulateSummary run_simulation(const SimulateOptions& options, const std::filesystem::path& out_dir,
                               const PhotonTransportProgress& progress = {});

/// The exit radiance per unit power (mm^-2 sr^-1) that a diffusion model predicts on the
/// simulation's pixel grid, each pixel averaged over 4 x 4 points (the entry point's pixel over 16
/// x 16).
imaging::ImageRgb model_radiance(const materials::Material& material, RadianceSource source,
                                 const PhotonTransportOptions& geometry);

/// The radiance image of a Lambertian reference of reflectance rho lit by the same beam (unit
/// power): rho / pi times a Gaussian spot of width sigma_mm integrated over each pixel (per mm^2),
/// so that the image integrated over the plane is rho / pi exactly, up to the spot's tail beyond
/// the grid.
imaging::ImageRgb white_reference_radiance(int size, double pixel_mm, double rho, double sigma_mm);

/// The image through a lens (SimulateOptions): a Gaussian blur of blur_mm, then the fraction
/// `glare` spread by the veiling-glare kernel of radius glare_radius_mm. Radiance per pixel in,
/// the same out (energy kept but for what leaves the field). Throws lucent::Error on bad values.
imaging::ImageRgb apply_lens(const imaging::ImageRgb& image, double pixel_mm, double blur_mm,
                             double glare, double glare_radius_mm);

/// The default field of a simulated capture (`lucent simulate` without --size or --pixel-mm): wide
/// enough for a fit to see 3.5 diffusion lengths (1 / sigma_tr), or 5 transport mean free paths, of
/// the slowest-falling channel beyond its exclusion radius; pixels a quarter of the shortest
/// transport mean free path (0.02..0.1 mm, coarser when the field would pass 1024 pixels). What is
/// given is kept; `why` says what was chosen ("" when nothing was).
struct SimulationField {
  int size = 0;
  double pixel_mm = 0;
  std::string why;
};
SimulationField default_simulation_field(const materials::Material& material, int size,
                                         double pixel_mm, bool size_given, bool pixel_given);

}  // namespace lucent::acquire
