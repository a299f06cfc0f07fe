// Monte Carlo photon transport in a homogeneous slab: the ground truth behind `lucent simulate`
// (docs/DESIGN.md §5). A pencil beam of unit power enters a flat sample at the origin; per colour
// channel the simulation records the specular, diffuse-reflected, transmitted and absorbed power,
// the radial exitance R(r), and an image of the radiance leaving toward an orthographic camera
// (next-event estimate at every scattering event). Deterministic for a seed, whatever the number of
// threads.
//
// Geometry: the sample fills z < 0 below the surface z = 0 (and ends at z = -thickness_mm when that
// is finite, with the same outside medium below). Lengths in mm, coefficients in mm^-1, angles in
// degrees.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "lucent/materials/medium.h"

namespace lucent::acquire {

/// How a packet that reaches the surface from inside is split between escape and internal
/// reflection.
enum class BoundaryScoring {
  /// Reflect with probability R (Fresnel), escape with the whole weight otherwise. The default: for
  /// equal variance of every tally it is faster than splitting (see photon_transport.cpp).
  kStochastic,
  /// MCML's scheme: the fraction 1 - R of the weight escapes and is scored, the rest reflects.
  kSplit,
};

/// Everything one simulation needs. Defaults give a 1e6-photon run of a semi-infinite slab lit
/// along the normal and seen along the normal.
struct PhotonTransportOptions {
  /// Per channel (R, G, B): sigma_a, sigma_s (mm^-1), Henyey-Greenstein g and eta = n_sample /
  /// n_air. A material known only through sigma_s' gives g = 0 (Material::medium()).
  std::array<materials::Medium<double>, 3> media{};
  /// Slab thickness, mm; infinity for a semi-infinite sample.
  double thickness_mm = std::numeric_limits<double>::infinity();
  /// A slab seen from its far side: the radial bins and the camera image record the light leaving
  /// the bottom surface (transmittance), the camera below looking up. The unscattered beam is in
  /// the totals (transmittance) but not in the bins or the image (a point at the centre). Needs a
  /// finite thickness.
  bool far_side = false;
  /// A beam of finite width: each photon enters at a point drawn from a round Gaussian of this
  /// sigma (mm) about the origin; 0: a pencil beam.
  double beam_sigma_mm = 0;
  /// Polar angle of the incident beam from the surface normal, degrees, in [0, 90).
  double incidence_deg = 0;
  /// Azimuth of the beam's direction of travel in the surface plane, degrees from +x: at 0 the beam
  /// travels toward +x (the light sits on the -x side).
  double azimuth_deg = 0;
  /// Photons per simulated channel (>= 1).
  std::uint64_t photons = 1'000'000;
  /// Seed of the random streams; each batch of kPhotonsPerBatch photons has its own stream derived
  /// from (seed, channel, batch index), so results do not depend on `threads`.
  std::uint64_t seed = 1;
  /// Worker threads; 0 = std::thread::hardware_concurrency().
  int threads = 0;
  /// Outer radius of the radial exitance bins, mm (> 0). Light leaving farther out still counts in
  /// diffuse_reflectance.
  double max_radius_mm = 100;
  /// Whether to record the camera image (next-event estimate at every scattering event).
  bool image = true;
  /// Image width and height, pixels, in [1, 16384].
  int size = 128;
  /// Pixel pitch on the sample surface, mm (> 0). The grid is centred on the entry point: pixel (i,
  /// j) covers x = (i + 0.5 - size/2) pixel_mm, y = (j + 0.5 - size/2) pixel_mm (+- half a pixel).
  double pixel_mm = 0.1;
  /// Polar angle of the direction toward the camera from the surface normal, degrees, in [0, 90).
  double view_deg = 0;
  /// Azimuth of the direction toward the camera in the surface plane, degrees from +x.
  double view_azimuth_deg = 0;
  /// Which channels to simulate (R, G, B); at least one.
  std::array<bool, 3> channels{true, true, true};
  /// How packets are scored at the boundaries.
  BoundaryScoring boundary_scoring = BoundaryScoring::kStochastic;
};

/// Photons per batch: the unit of work and of random streams. Changing it changes the results.
inline constexpr std::uint64_t kPhotonsPerBatch = 4096;

/// A Monte Carlo mean over photons and its standard error (standard deviation of the per-photon
/// values / sqrt(photons); infinity with fewer than two photons).
struct Estimate {
  double value = 0;
  double standard_error = 0;
};

/// One annulus of the radial exitance, mm.
struct ExitanceBin {
  double r_inner_mm = 0;
  double r_outer_mm = 0;
  double r_centre_mm = 0;  ///< area-weighted mean radius, 2/3 (r_o^3 - r_i^3) / (r_o^2 - r_i^2)
};

/// The annuli used for max_radius_mm: 0.01 mm wide up to 0.5 mm, then each 5% wider than the one
/// before, the last one ending exactly at max_radius_mm (a sliver narrower than half a bin joins
/// its neighbour).
std::vector<ExitanceBin> exitance_bins(double max_radius_mm);

/// The results of one channel; all per unit incident power.
struct ChannelTransportResult {
  /// Photons simulated; 0 when the channel was not selected (then everything else is empty or NaN).
  std::uint64_t photons = 0;
  /// Power leaving through the top surface after entering (specular excluded).
  Estimate diffuse_reflectance;
  /// Fresnel reflection of the beam at entry (exact: its standard error is 0).
  Estimate specular_reflectance;
  /// Power leaving through the bottom surface (finite slab); 0 for a semi-infinite slab unless
  /// sigma_t = 0, when the refracted beam is lost to infinite depth and counted here.
  Estimate transmittance;
  /// Power absorbed, with Russian roulette booked exactly (see photon_transport.cpp), so that
  /// diffuse + specular + transmittance + absorbed = 1 photon by photon up to rounding.
  Estimate absorbed;
  /// Radial exitance R(r), mm^-2, one per exitance_bins(max_radius_mm) entry.
  std::vector<Estimate> exitance;
  /// Radiance toward the camera, mm^-2 sr^-1, size * size values, pixel (i, j) at [j * size + i]
  /// (rows along +y). Empty when options.image is false; all zero when no direction inside the
  /// sample refracts toward the camera (eta < 1 and view_deg beyond the critical angle).
  std::vector<double> image;
  /// Standard error of each image value, mm^-2 sr^-1 (per-photon sums of squares).
  std::vector<double> image_standard_error;
  /// Sum over the grid of image * pixel area: radiance integrated over the imaged surface, sr^-1.
  Estimate image_integral;
  /// Mean number of interactions (collisions) per photon: the cost driver.
  double mean_interactions = 0;
  /// Photons stopped after kMaxInteractionsPerPhoton interactions (only for albedo within ~1e-6 of
  /// 1 in a thick sample); their remaining weight is booked as absorbed.
  std::uint64_t photons_truncated = 0;
};

/// Safety cap on collisions per photon; see ChannelTransportResult::photons_truncated.
inline constexpr std::uint64_t kMaxInteractionsPerPhoton = 10'000'000;

struct PhotonTransportResult {
  PhotonTransportOptions options;  ///< as given (threads as given, 0 included)
  std::vector<ExitanceBin> bins;   ///< exitance_bins(options.max_radius_mm)
  std::array<ChannelTransportResult, 3> channels;
  std::uint64_t seed = 0;   ///< options.seed
  int threads_used = 0;     ///< worker threads actually started
  double wall_seconds = 0;  ///< elapsed time of the whole simulation
};

/// Called after each batch is merged (from one thread at a time), with photons merged so far and
/// the total over all selected channels. An exception thrown here stops the simulation and
/// propagates.
using PhotonTransportProgress =
    std::function<void(std::uint64_t photons_done, std::uint64_t photons_total)>;

/// Throws lucent::Error naming the first option that is out of range.
void validate_photon_transport_options(const PhotonTransportOptions& options);

/// Runs the simulation (validates first).
PhotonTransportResult simulate_photon_transport(const PhotonTransportOptions& options,
                                                const PhotonTransportProgress& progress = {});

/// The radial exitance as CSV: `#` comment lines with key=value tokens (format, photons, seed, the
/// geometry, the four totals and their standard errors as R,G,B), then the header
/// `r_mm,R_r,R_g,R_b,se_r,se_g,se_b,r_inner_mm,r_outer_mm` and one row per bin (r_mm =
/// area-weighted centre, values mm^-2, the annulus in mm), 17 significant digits. Channels not
/// simulated leave their fields empty.
std::string exitance_csv(const PhotonTransportResult& result);

}  // namespace lucent::acquire
