// The oblique transport table a fit of 2D oblique captures needs (no CLI11 here).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lucent/fit/fit.h"
#include "lucent/materials/transport_table.h"

namespace lucent::cli {

/// The table holding the slice (eta, g, incidence) of these data, or nothing when they need none
/// (radial data, a dipole model, --fit-ior, `given` "none"). In order: `given` (--oblique-table; an error when it
/// lacks the slice), the shipped table, the cache (materials::oblique_cache_dir()), else the slice
/// is built now with `photons` photons (progress on stderr unless quiet) and kept in the cache.
std::optional<materials::TransportTable> oblique_table_for(
    const std::vector<fit::ProfileData>& data, const fit::FitOptions& options,
    const std::string& given, std::uint64_t photons, bool quiet);

}  // namespace lucent::cli
