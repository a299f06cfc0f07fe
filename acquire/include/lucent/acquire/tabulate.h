// `lucent tabulate`: builds the transport table of the tabulated model (docs/DESIGN.md §4.2) by
// "white" Monte Carlo: one absorption-free run per (eta, g) serves every albedo, absorption applied
// afterwards through each path's length (see tabulate.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "lucent/materials/transport_table.h"

namespace lucent::acquire {

struct TabulateOptions {
  std::vector<double> eta{1.0, 1.1, 1.2, 1.3,
                          1.4, 1.5, 1.6};  ///< relative indices, each in [1, 2.5]
  std::vector<double> g{0.0};              ///< Henyey-Greenstein mean cosines, each in [0, 0.99]
  /// Incidence angles from the normal (degrees, [0, 85]); any > 0 needs grid.phi_bins > 1.
  std::vector<double> incidence_deg{0.0};
  materials::TransportTableGrid grid = materials::default_transport_grid();
  std::uint64_t photons = 1'000'000;  ///< per slice (rounded up to a multiple of groups)
  /// Photons of the white run (the nodes of alpha' >= 0.4) per slice; 0: `photons`. Fewer make
  /// high-g slices affordable (a white path costs 1 / (1 - g) collisions per transport length);
  /// the entries' standard errors say what it costs in noise.
  std::uint64_t white_photons = 0;
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0: all cores
  int groups = 16;  ///< independent photon groups per slice, >= 2
  /// Paths are cut at this length in units of 1 / sigma_s' (a photon that long has, at the table's
  /// smallest nonzero 1 - alpha', kept less than e^-40 of its weight; only the alpha' = 1 node
  /// loses anything, and only far out).
  double max_path = 2e5;
  /// A slab instead of a semi-infinite sample: its thickness in units of 1 / sigma_s' (d sigma_s',
  /// the white run's own length unit, so that one white run still serves every albedo; the direct
  /// runs of albedo a walk d sigma_t' = thickness_s / a). Infinity: semi-infinite. Normal incidence
  /// only. The same outside medium below as above.
  double thickness_s = std::numeric_limits<double>::infinity();
  /// With a finite thickness_s: tally the light leaving the far side (transmittance: exitance and
  /// the radiance along the outward normal below), not the lit side. The unscattered beam (a point
  /// at rho = 0) is in neither the bins nor the totals.
  bool transmitted = false;
  int shard_index = 0;  ///< this shard, in [0, shard_count)
  int shard_count = 1;  ///< > 1: write a partial table of every shard_count-th (slice, group)
};

/// Progress: photons traced so far and in all (this shard's).
using TabulateProgress = std::function<void(std::uint64_t done, std::uint64_t total)>;

/// Throws lucent::Error naming the first bad option.
void validate_tabulate_options(const TabulateOptions& options);

/// Builds the table, or with shard_count > 1 a partial one. Deterministic for a seed whatever the
/// threads and the sharding (a merge of all shards equals the unsharded table bit for bit).
materials::TransportTable tabulate_transport(const TabulateOptions& options,
                                             const TabulateProgress& progress = {});

}  // namespace lucent::acquire
