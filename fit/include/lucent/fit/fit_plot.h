// The fit plot (.svg, .pdf or .png by extension): the profile, data as markers with +-1 SE error
// bars per channel and the fitted model as lines on a log y axis (log r on request); below it,
// on the same x axis, the residuals in standard errors with lines at 0 and +-2; for captures with
// 2D samples a residual map per channel over the image plane; the parameters as footer text.
#pragma once

#include <filesystem>
#include <string>

#include "lucent/fit/fit.h"

namespace lucent::fit {

struct FitPlotOptions {
  bool log_r = false;  ///< logarithmic r axis (the profile and its residuals)
};

/// Writes the plot of `result` against `data` (the first capture of the fit) atomically. Oblique
/// captures (2D samples) show their data and the model, computed per pixel as the fit does,
/// averaged over the same pixels in radial bins. Throws lucent::Error naming the file.
void write_fit_plot(const std::filesystem::path& path, const FitResult& result,
                    const ProfileData& data, FitPlotOptions options = {});

/// Throws lucent::Error "<option>: '<path>': expected a file ending in .svg, .pdf or .png" unless
/// `path` names a format write_fit_plot writes.
void check_fit_plot_path(const std::filesystem::path& path, const std::string& option);

/// The fitted model's prediction (pi L / P per mm^2 including both Fresnel transmittances and the
/// global scale) at radius r at normal incidence on a plane, channel c.
double predicted_radial(const ModelFit& fit, const ProfileData& data, int channel, double r_mm,
                        const materials::TabulatedProfile* table = nullptr);

}  // namespace lucent::fit
