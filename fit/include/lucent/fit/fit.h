// `lucent fit`: optical coefficients from measured profiles with Ceres (docs/DESIGN.md §6).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/fit/fit_data.h"
#include "lucent/materials/material.h"

namespace lucent::materials {
class TabulatedProfile;
struct TransportTable;
struct SlabNodes;
}  // namespace lucent::materials

namespace lucent::fit {

/// kTabulated: the transport table (docs/DESIGN.md §4.2), exact to radiative transfer for radial
/// profiles at normal incidence and normal view. kAuto: the accurate model the data allows
/// (tabulated for radial data, the directional dipole for oblique 2D data), then which cheaper
/// model is adequate.
enum class FitModel { kDipole, kDirectionalDipole, kTabulated, kAuto };
std::string to_string(FitModel model);
/// "auto", "tabulated", "dipole" or "ddipole"; anything else throws lucent::Error naming `option`.
FitModel parse_fit_model(const std::string& name, const std::string& option = "--model");
enum class Quality { kFast, kBalanced, kAccurate };
/// "fast", "balanced" or "accurate"; anything else throws lucent::Error naming `option`.
Quality parse_quality(const std::string& name, const std::string& option = "--quality");
enum class LossKind { kNone, kHuber, kCauchy };

struct FitOptions {
  FitModel model = FitModel::kAuto;
  /// Bins (and 2D samples) closer to the entry point than this are left out, mm, in every channel.
  /// Unset: per channel from its own data: for the diffusion models one transport mean free path
  /// 1 / sigma_t' (single scattering, which they lack, lives inside it); for the tabulated model,
  /// which has it, two pixels (the footprint quadrature cannot follow the 1/r peak) or
  /// 0.1 / sigma_t'.
  std::optional<double> exclude_radius_mm;
  /// Henyey-Greenstein g the tabulated model assumes (radial normal-incidence data cannot separate
  /// g from sigma_s; the report says how far the answer moves between g = 0 and 0.9).
  double g = 0;
  /// The transport table; null: the shipped one (materials::default_transport_table()).
  const materials::TransportTable* table = nullptr;
  /// The sample is a slab this thick (mm), for every input (over what the inputs say); absent:
  /// what each input says (thickness_mm, side), else semi-infinite.
  std::optional<double> thickness_mm;
  /// The sample is a slab of unknown thickness, fitted (one for every input; the lit side's
  /// tables needed, as for thickness_mm): FitResult::thickness says how well the data pin it.
  bool fit_thickness = false;
  /// A slab's tables at the data's (eta, g) (lucent fit builds them: cli/fit_tables.h); needed
  /// when any input is a slab. The lit side's nodes without the semi-infinite one (the fit adds
  /// its own table's).
  std::shared_ptr<const materials::SlabNodes> slab;
  /// The beam (and lens) as a round Gaussian of this sigma, mm, for every input, over any system
  /// response the inputs carry; 0: each input's measured response (the white reference's) where
  /// it is wider than the pixels (its core's rms radius above 2 pixels, or 2% glare), else a
  /// pencil beam.
  double beam_sigma_mm = 0;
  /// An oblique table (lucent tabulate --incidence-deg) holding the slice at the data's eta, g
  /// and incidence: 2D oblique data are then fitted with it, exact to transport. Null, or no
  /// such slice: the directional dipole corrected by the radial table (a note says so).
  const materials::TransportTable* oblique_table = nullptr;
  /// The model-error work beside the solve: a diffusion model's cross-fit of the tabulated model,
  /// the tabulated model's bootstrap over its table and accuracy refits, the g = 0.9 refit, the
  /// adequacy of cheaper models. Off only to time the solve alone (bench_fit).
  bool systematics = true;
  std::optional<double> ior;     ///< relative index; required unless the data carries it or fit_ior
  bool fit_ior = false;          ///< fit eta too (one for all channels)
  std::optional<bool> relative;  ///< fit a global scale; default: when the data is uncalibrated
  LossKind loss = LossKind::kNone;
  double loss_scale = 1.0;  ///< in standard errors
  Quality quality = Quality::kBalanced;
  /// Hand-written Jacobian for the standard dipole on radial bins (the common case); automatic
  /// derivatives (ceres::Jet) otherwise. Same answer (tests/fit), measured faster (bench_fit).
  bool analytic_derivatives = true;
  bool allow_unconverged = false;
  int max_iterations = 0;  ///< solver iterations at most; 0 = what --quality sets
  /// Solver iterations of the tabulated model's bootstrap and accuracy refits (its systematic).
  /// They start at the answer and move from it by a fraction of its SD, so 3 solver steps reach
  /// their solution (the systematic SDs within 2.5% of converged refits' on a 128x128 oblique
  /// capture, 14% at 2 steps; issue 37); 0 = to convergence, as the fit itself.
  int systematic_refit_iterations = 3;
  /// Start values per channel {sigma_a, sigma_s'} in mm^-1 instead of the data's (far-field slope
  /// and total reflectance); for tests and for users who know better.
  std::optional<std::array<std::array<double, 2>, 3>> start;
  /// Told which stage starts and the share of the work done before it (for a progress line);
  /// optional. The shares are those measured on an oblique capture, where a fit takes seconds.
  std::function<void(const std::string& stage, double done)> progress;
};

/// The knobs a Quality sets.
struct QualitySettings {
  int footprint_order = 2;    ///< Gauss-Legendre points across each bin or pixel footprint
  int max_samples_2d = 4096;  ///< 2D samples used at most (subsampled evenly)
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  int max_iterations = 100;
};
QualitySettings quality_settings(Quality quality);

struct ChannelFit {
  double sigma_a = 0, sigma_s_reduced = 0;  ///< mm^-1
  /// Total standard deviations, mm^-1 (0 when fixed): statistical and systematic in quadrature.
  double sd_sigma_a = 0, sd_sigma_s_reduced = 0;
  /// Statistical: from the Jacobian (calibration priors included), scaled by the square root of
  /// the larger of the reduced chi^2 (lack of fit) and, for single pixels, the design effect,
  /// when it exceeds 1.
  double sd_stat_sigma_a = 0, sd_stat_sigma_s_reduced = 0;
  /// Systematic: the model's own error; for a diffusion model its difference from the tabulated
  /// model on the same data (0 for the tabulated model, whose table error enters the statistical
  /// part through the weights).
  double sd_sys_sigma_a = 0, sd_sys_sigma_s_reduced = 0;
  double reduced_chi2 = 0;
  /// Single pixels (2D samples): the variance of the residuals' sums over 1-8 mm cells relative
  /// to independent unit-variance noise (pixel-to-pixel correlated or unmodelled noise); 1
  /// otherwise.
  double design_effect = 1;
  /// Structure left along the radius by the accurate model (radial data): how far, in standard
  /// normal deviates, the runs of one sign in the residuals are beyond what noise makes (0 when not
  /// judged: fewer than 24 bins, or a diffusion model, whose own error is its systematic).
  double structure_z = 0;
  /// This channel's usable range: exclusion radius and the last bin above the noise floor, mm.
  double exclude_radius_mm = 0, range_end_mm = 0;
  /// The usable range in diffuse mean free paths 1 / sigma_tr (the fit's sigma_tr).
  double range_diffusion_lengths = 0;
  double correlation = 0;  ///< between sigma_a and sigma_s'
  double start_sigma_a = 0, start_sigma_s_reduced = 0;
  int samples = 0;          ///< residuals used
  double residual_rms = 0;  ///< in standard errors
  /// 1.4826 x median |residual|, standard errors: what decides whether the fit describes its data
  /// (above 10 it does not, and the fit is not called converged).
  double robust_residual_rms = 0;
  double chi2 = 0;
};

struct ModelFit {
  FitModel model = FitModel::kDipole;
  std::array<ChannelFit, 3> channels;
  double eta = 1.3;
  double sd_eta = 0;
  double scale = 1.0, sd_scale = 0;  ///< global scale (1 when calibrated and not fitted)
  /// The Gaussian beam the fit assumed (FitOptions::beam_sigma_mm; 0: the data's own response).
  double beam_sigma_mm = 0;
  /// Per channel, the first input's calibration scale as fitted within its prior (1 when exact).
  std::array<double, 3> calibration_scale{1.0, 1.0, 1.0};
  bool converged = false;
  int iterations = 0;
  double time_ms = 0;  ///< solve + covariance, ms
  double chi2 = 0;     ///< sum of squared residuals over all channels
  int samples = 0;
  int parameters = 0;
  double aic = 0, bic = 0;
  std::vector<std::string> undetermined;  ///< parameter combinations the data cannot determine
  std::string message;                    ///< Ceres' termination message
};

/// How well a cheaper model reproduces the chosen (accurate) material: its profile evaluated with
/// the chosen coefficients against the chosen model's, over the data's radii.
struct ModelAdequacy {
  /// The bar for "adequate": within this relative deviation of the accurate profile beyond a radius
  /// in the first half of the data's reach. The text, the file and the test use this one number.
  static constexpr double kBar = 0.03;
  FitModel model = FitModel::kDipole;
  /// The tightest of the bands 3, 5, 10, 20, 50% (relative) the model keeps beyond `beyond_mm`.
  double tolerance = kBar;
  /// Beyond this radius (mm) the cheaper profile stays within `tolerance` in every channel up to
  /// the end of the data; infinity when it never does.
  double beyond_mm = 0;
  double max_deviation = 0;  ///< worst relative deviation beyond the exclusion radius
  bool adequate = false;     ///< within tolerance beyond a radius inside the data
};

/// A fitted slab thickness (FitOptions::fit_thickness), mm.
struct ThicknessFit {
  /// The best fit; infinity when the data fit a semi-infinite sample as well as any thick slab.
  double thickness_mm = 0;
  /// The 1 SD interval (chi^2 within max(1, reduced chi^2) of its minimum); lower 0 or upper
  /// infinity where it is open (the data allow any thinner or thicker slab).
  double lower_mm = 0, upper_mm = 0;
  bool determined = false;  ///< both ends closed
  int fits = 0;             ///< coefficient fits the search took
};

struct FitResult {
  ModelFit chosen;
  std::vector<ModelFit> candidates;     ///< every model fitted (auto: accurate first)
  std::string reason;                   ///< why this model
  double exclude_radius_mm = 0;         ///< the smallest of the channels' exclusion radii
  std::vector<std::string> notes;       ///< assumptions worth saying (assumed errors, ...)
  std::vector<std::string> warnings;    ///< results to distrust (short range, parameters at bounds)
  std::vector<ModelAdequacy> adequacy;  ///< cheaper models against the chosen one
  /// The cheapest adequate one; "none" when none is, "" when not judged (no accurate model).
  std::string adequate_model;
  /// What a renderer without the accurate model's table uses: the adequate model, else the closest
  /// one (tightest band, then smallest radius). "" when not judged.
  std::string fallback_model;
  double g = 0;                         ///< the g the tabulated model assumed
  /// A semi-infinite fit: the thinnest sample for which that answer holds (mm; 0 for a slab fit).
  double assumed_thickness_mm = 0;
  /// --fit-thickness: the thickness found.
  std::optional<ThicknessFit> thickness;
  /// Per channel {sigma_a, sigma_s'} of the tabulated fit at g = g_other (0.9, or 0 when the fit
  /// assumed g >= 0.45): how far the answer moves with the assumed g. Empty when not computed.
  std::vector<std::array<double, 2>> g_09;
  double g_other = 0.9;
  /// The tabulated profile the fit used (for plots); null when none.
  std::shared_ptr<const materials::TabulatedProfile> table;
};

/// Fits one or more profiles of one material jointly.
FitResult fit_profiles(const std::vector<ProfileData>& data, const FitOptions& options);

/// The material file for a fit: coefficients, model, uncertainty, provenance.fit.
materials::Material fitted_material(const FitResult& result, const std::vector<ProfileData>& data,
                                    const FitOptions& options, const std::string& name);

/// Everything per channel, for report.json.
nlohmann::json fit_report(const FitResult& result, const std::vector<ProfileData>& data,
                          const FitOptions& options);

}  // namespace lucent::fit
