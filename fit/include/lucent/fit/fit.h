// `lucent fit`: optical coefficients from measured profiles with Ceres (DESIGN §6).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/fit/fit_data.h"
#include "lucent/materials/material.h"

namespace lucent::fit {

enum class FitModel { kDipole, kDirectionalDipole, kAuto };
enum class Quality { kFast, kBalanced, kAccurate };
enum class LossKind { kNone, kHuber, kCauchy };

struct FitOptions {
  FitModel model = FitModel::kAuto;
  /// Bins (and 2D samples) closer to the entry point than this are left out (single scattering and
  /// the specular peak live there), mm. Unset: one transport mean free path 1 / sigma_t', estimated
  /// from the data's start values.
  std::optional<double> exclude_radius_mm;
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
  /// Start values per channel {sigma_a, sigma_s'} in mm^-1 instead of the data's (far-field slope
  /// and total reflectance); for tests and for users who know better.
  std::optional<std::array<std::array<double, 2>, 3>> start;
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
  double sigma_a = 0, sigma_s_reduced = 0;        ///< mm^-1
  double sd_sigma_a = 0, sd_sigma_s_reduced = 0;  ///< standard deviations, mm^-1 (0 when fixed)
  double correlation = 0;                         ///< between sigma_a and sigma_s'
  double start_sigma_a = 0, start_sigma_s_reduced = 0;
  int samples = 0;          ///< residuals used
  double residual_rms = 0;  ///< in standard errors
  double chi2 = 0;
};

struct ModelFit {
  FitModel model = FitModel::kDipole;
  std::array<ChannelFit, 3> channels;
  double eta = 1.3;
  double sd_eta = 0;
  double scale = 1.0, sd_scale = 0;  ///< global scale (1 when calibrated and not fitted)
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

struct FitResult {
  ModelFit chosen;
  std::vector<ModelFit> candidates;  ///< every model fitted (auto: both)
  std::string reason;                ///< why this model
  double exclude_radius_mm = 0;
  std::vector<std::string> notes;  ///< assumptions worth saying (assumed errors, ...)
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
