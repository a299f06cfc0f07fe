// --fit-thickness: a slab's thickness from its profiles (profile likelihood over the thickness,
// the coefficients fitted at each trial). Internal to lucent_fit.
#pragma once

#include <vector>

#include "lucent/fit/fit.h"

namespace lucent::fit::detail {

/// The fit at the thickness that fits best (FitOptions::fit_thickness), with FitResult::thickness
/// set and the coefficients' spread over its 1 SD interval in their systematic. Throws
/// lucent::Error when the options cannot go with a fitted thickness.
FitResult fit_unknown_thickness(const std::vector<ProfileData>& data, const FitOptions& options);

}  // namespace lucent::fit::detail
