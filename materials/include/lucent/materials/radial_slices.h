// Radial transport-table slices at exactly one (eta, g), built by `lucent fit` when the shipped
// table has none there (a g between its nodes or past them) and kept in the cache
// (oblique_cache_dir()): where they live, how they are found again, and the one rule by which
// everything outside a fit (lucent profile, the renderers) picks the table of a (g, eta).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"

namespace lucent::materials {

/// The cache file's name of the slice at (eta, g) built with `photons` photons per albedo node.
std::string radial_slice_file_name(double eta, double g, std::uint64_t photons);

/// The cached slice at exactly (eta, g) of the most photons that reads, looked up once per process
/// (a slice built later in the same process is not seen) and kept for it; nullptr when the cache
/// holds none.
const TransportTable* cached_radial_slice(double eta, double g);

/// Keeps a table for the rest of the process: a stable address, which cached_tabulated_profile
/// keys its prepared profiles by (a table that dies and another born at its address would be
/// taken for it).
const TransportTable& keep_transport_table(TransportTable table);

/// The prepared profile a tabulated model of (g, eta) uses: the cached slice at exactly (eta, g)
/// when a fit built one, else the shipped table at g (a node, or C1 in g
/// between nodes), at eta. Throws lucent::Error like cached_tabulated_profile when neither holds
/// it.
std::shared_ptr<const TabulatedProfile> radial_profile_for(double g, double eta);

}  // namespace lucent::materials
