// The transport tables a fit needs beyond the shipped ones, found in the cache or built now: the
// oblique slice of 2D oblique captures, the radial slice of a g outside the radial table (no
// CLI11 here).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lucent/fit/fit.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"

namespace lucent::cli {

/// The table holding the slice (eta, g, incidence) of these data, or nothing when they need none
/// (radial data, a dipole model, --fit-ior, `given` "none"). In order: `given` (--oblique-table; an
/// error when it lacks the slice), the shipped table, the cache (materials::oblique_cache_dir()),
/// else the slice is built now with `photons` photons (progress on stderr unless quiet) and kept in
/// the cache.
std::optional<materials::TransportTable> oblique_table_for(
    const std::vector<fit::ProfileData>& data, const fit::FitOptions& options,
    const std::string& given, std::uint64_t photons, bool quiet);

/// The radial table of these data when the shipped table has no slice at their g (a g between its
/// nodes or beyond them), or null when it has one or they need none (a table given with --table,
/// 2D or oblique data, a dipole model, --fit-ior, no index). The slice at exactly (eta, g) comes
/// from the cache, else is built now with `photons` photons per albedo node (the white run's scaled
/// by 1.5 (1 - g): a minute per million here whatever g) on the default grid with near-black nodes
/// down to alpha' 2e-4, and kept in the cache (materials::radial_slice_file_name) and for the
/// process.
const materials::TransportTable* radial_table_for(const std::vector<fit::ProfileData>& data,
                                                  const fit::FitOptions& options,
                                                  std::uint64_t photons, bool quiet);

/// The grid of a radial slice built for a fit: the shipped table's, with albedo nodes down to
/// alpha' = 2e-4 (near-black media of high g, where the shipped table's last node, alpha' = 0.004,
/// still scatters a sixth of the light at g = 0.98).
materials::TransportTableGrid radial_fit_grid();

/// The thickness nodes of a slab's tables, d sigma_s': 0.25 to 64 in factors of 2.
const std::vector<double>& slab_thickness_nodes();

/// The slab's tables of these data (any input with a thickness, from it or --thickness-mm), null
/// when none is a slab or the model is not tabulated: at the data's eta and the fit's g, one
/// table per thickness node and side the data need (lit side always: the fit starts there), from
/// the cache or built now with `photons` photons each (progress on stderr unless quiet) and kept.
std::shared_ptr<const materials::SlabNodes> slab_nodes_for(const std::vector<fit::ProfileData>& data,
                                                          const fit::FitOptions& options,
                                                          std::uint64_t photons, bool quiet);

}  // namespace lucent::cli
