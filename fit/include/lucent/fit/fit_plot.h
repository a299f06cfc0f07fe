// fit.png: the data with error bars and the fitted curve against r on a log axis, residuals below,
// one colour per channel, the parameters printed underneath.
#pragma once

#include <filesystem>

#include "lucent/fit/fit.h"

namespace lucent::fit {

void write_fit_plot(const std::filesystem::path& path, const FitResult& result,
                    const ProfileData& data);

/// The fitted model's prediction (pi L / P per mm^2 including both Fresnel transmittances and the
/// global scale) at radius r at normal incidence on a plane, channel c.
double predicted_radial(const ModelFit& fit, const ProfileData& data, int channel, double r_mm,
                        const materials::TabulatedProfile* table = nullptr);

}  // namespace lucent::fit
