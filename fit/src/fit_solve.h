// The Ceres problem of a fit (docs/DESIGN.md §6): residuals (log-ratio of model to data in units of
// the relative standard error) for every model, the solve, the covariance from the Jacobian with
// undetermined directions named, per-channel statistics. Internal to lucent_fit.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include "fit_start.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/tabulated.h"

namespace lucent::fit::detail {

/// The channels by name, in messages and parameter names.
inline constexpr const char* kChannelNames[3] = {"R", "G", "B"};

/// A channel whose residuals have a robust rms (1.4826 x median |r|) above this many standard
/// errors does not fit its data, and the fit is not called converged. A good fit has about 1; up
/// to here a model's lack of fit (the directional dipole on oblique Monte Carlo captures reaches
/// 8.5) is carried into the reported SDs by the Birge ratio; the fits that end far off the data
/// have 59 to 14,000.
inline constexpr double kMaxFittedRms = 10.0;

// A smooth relative change of the model, e^(epsilon shape(log10 rho)): how the tabulated model's
// own error (its measured accuracy against fresh Monte Carlo) moves the answer.
struct ModelPerturbation {
  double epsilon = 0;
  int shape = 0;  // 1: tilt across log rho in [-2, 2]; 2: a bow over the same range
  template <typename T>
  T factor(const T& rho) const {
    using std::exp;
    using std::log10;
    if (epsilon == 0) return T(1);
    T x = log10(rho) / T(2);
    if (x < T(-1)) x = T(-1);
    if (x > T(1)) x = T(1);
    return exp(T(epsilon) * (shape == 1 ? x : T(2) * x * x - T(1)));
  }
};

/// One solve of `model` from `start`, with each channel's exclusion radius; counts the samples
/// left out below the noise floor into *below_noise. hold_sigma_a: per channel a sigma_a (mm^-1)
/// to hold fixed, or <= 0 for free.
ModelFit solve(const std::vector<ProfileData>& data, const FitOptions& options, FitModel model,
               const materials::TabulatedProfile* table, double eta0, bool relative,
               const std::array<double, 3>& exclude, const std::array<StartValues, 3>& start,
               std::array<bool, 3> channels, int* below_noise,
               ModelPerturbation perturbation = {},
               const std::array<double, 3>* hold_sigma_a = nullptr);

}  // namespace lucent::fit::detail
