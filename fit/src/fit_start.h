// Start values of a fit from the data alone (docs/DESIGN.md §6): the far-field log-slope gives
// sigma_tr, the total reflectance (closed-form dipole inversion) gives alpha'; a coarse grid search
// when the profile has no exponential tail. Internal to lucent_fit.
#pragma once

#include "lucent/fit/fit_data.h"

namespace lucent::fit::detail {

struct StartValues {
  double sigma_a = 0.01, sigma_s_reduced = 1.0, log_scale = 0.0;
};

/// Start values of channel c from the first profile's radial bins; `search` adds the grid search.
StartValues start_values(const ProfileData& d, int c, double eta, bool relative, bool search);

}  // namespace lucent::fit::detail
