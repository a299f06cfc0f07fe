// After the solves: total uncertainty (statistical and the model's own systematic error), the
// warnings a result needs, and which cheaper model reproduces the accurate one (docs/DESIGN.md §6).
// Internal to lucent_fit.
#pragma once

#include <array>
#include <vector>

#include "lucent/fit/fit.h"

namespace lucent::fit::detail {

/// Systematics of the diffusion candidates (their difference from the tabulated fit on the same
/// data), totals, range warnings, an eta at the edge of its range named undetermined.
void finish_uncertainty(FitResult& result, const FitOptions& options,
                        const std::array<bool, 3>& channels);

/// result.adequacy and result.adequate_model for a tabulated fit: the dipoles' profiles with the
/// fitted coefficients against the table's, over the data's usable radii.
void judge_adequacy(FitResult& result, const std::vector<ProfileData>& data,
                    const std::array<bool, 3>& channels);

}  // namespace lucent::fit::detail
