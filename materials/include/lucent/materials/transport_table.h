// The transport table behind the `tabulated` model (docs/DESIGN.md §4.2): the radial profile of a
// semi-infinite slab under a normally incident pencil beam, from lucent's Monte Carlo simulator,
// in optical units (radius times sigma_t', reduced albedo alpha') per relative index eta and
// Henyey-Greenstein g. This header is the data and its file; `tabulated.h` interpolates it.
// An oblique table (`phi_bins` > 1, slices with an incidence angle) holds the 2D profile of a
// beam arriving at incidence_deg from the normal, travelling toward +x: each radius bin split
// into phi_bins wedges of azimuth phi = atan2(|y|, x) in [0, pi] (the profile is even in y);
// `oblique.h` interpolates it.
//
// File (`lucent-transport-table`, version 1): one line of JSON describing everything (format,
// version, units, grid, photons and seed per slice, payload layout and its CRC-32), a newline, then
// the payload: little-endian binary, per slice in order, per quantity (exitance, radiance), a
// float32 value and a uint8 standard-error code per (u, rho) entry, then float64 totals. Binary
// because the shipped table must stay small in git (docs/DESIGN.md §4.2; the JSON header keeps it
// self-describing); a `partial` file from `lucent tabulate --shard` holds per-group sums instead.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace lucent::materials {

/// What a table entry measures, per unit power entering the sample (the beam's specular reflection
/// excluded), divided by sigma_t'^2 (so that rho = r sigma_t' is the only length).
enum class TableQuantity {
  /// Radial exitance R(r): power leaving the surface per unit area, all directions.
  kExitance = 0,
  /// pi times the radiance leaving along the surface normal (what a camera looking straight down
  /// sees, the exit Fresnel transmittance and the n^2 law included).
  kRadiance = 1,
};
inline constexpr int kTableQuantities = 2;
const char* to_string(TableQuantity q);

/// The axes. Radii: bins (annuli) log-spaced in rho = r sigma_t' from rho_min to rho_max,
/// rho_per_decade of them per decade; values are annulus averages. Albedo: nodes in
/// u = sqrt(1 - alpha'), ascending from 0 (alpha' = 1), where the profile is smooth (diffusion's
/// sigma_tr / sigma_t' = sqrt(3) u).
struct TransportTableGrid {
  std::vector<double> u;
  double rho_min = 0.01;
  double rho_max = 100;
  int rho_per_decade = 20;
  /// Azimuth wedges per radius bin over [0, pi]: 1 for a radial (normal-incidence) table.
  int phi_bins = 1;

  int rho_bins() const;
  double rho_edge(int j) const;    ///< j in [0, rho_bins()]
  double rho_centre(int j) const;  ///< geometric centre of bin j
  /// Rows of rho_bins() entries: one per (u node, azimuth wedge), index k * phi_bins + p.
  std::size_t rows() const { return u.size() * std::size_t(phi_bins); }
  std::size_t entries() const { return rows() * std::size_t(rho_bins()); }
  bool operator==(const TransportTableGrid&) const = default;
};

/// The default grid of the shipped table.
TransportTableGrid default_transport_grid();
/// The default grid of an oblique table: the same albedo nodes, rho 0.05..100 at 16 per decade,
/// 12 azimuth wedges of 15 degrees.
TransportTableGrid default_oblique_grid();

/// Standard-error code: 255 marks an entry with no Monte Carlo support (its value is a far-tail
/// extrapolation); otherwise the relative standard error is 10^((code - 200) / 40), 1e-5 to ~20,
/// a 6% step.
std::uint8_t encode_relative_se(double relative_se, bool extrapolated);
double decode_relative_se(std::uint8_t code);  ///< infinity for 255
inline constexpr std::uint8_t kExtrapolatedEntry = 255;

/// One (eta, g, incidence) slice.
struct TransportTableSlice {
  double eta = 1;
  double g = 0;
  double incidence_deg = 0;  ///< the beam's angle from the normal, outside the medium
  std::uint64_t white_photons = 0;  ///< behind the white nodes (alpha' >= 0.4); 0: `photons`
  std::uint64_t photons = 0;  ///< photons behind every entry of the slice
  /// [quantity][row * rho_bins + j] (rows as TransportTableGrid::rows()): bin-average value and
  /// standard-error code.
  std::array<std::vector<float>, kTableQuantities> value;
  std::array<std::vector<std::uint8_t>, kTableQuantities> se_code;
  /// Per u node: total diffuse reflectance (exitance over the whole plane) and its standard error.
  std::vector<double> total, total_se;
};

/// Per-group sums of a shard (`lucent tabulate --shard`), merged into a table by
/// finish_transport_table. Group tallies are means over the group's photons.
struct TransportTableGroup {
  int slice = 0;  ///< index into the table's slices
  int group = 0;
  std::array<std::vector<double>, kTableQuantities> value;  ///< bin averages
  std::vector<double> total;
};

struct TransportTable {
  TransportTableGrid grid;
  std::uint64_t seed = 1;
  int groups = 16;             ///< independent photon groups per slice (standard errors from them)
  double max_path = 0;         ///< photon paths cut at this length, in units of 1 / sigma_s'
  std::string generator;       ///< lucent version that built it
  std::vector<TransportTableSlice> slices;  ///< finished slices (empty in a partial file)
  bool partial = false;                     ///< a shard: groups instead of slices
  std::string shard;                        ///< "I/N" for a shard
  std::vector<TransportTableGroup> partial_groups;
  /// Slice axes (eta, g, photons per slice, incidence in degrees, white-run photons or 0 for the
  /// same), the slices' order.
  std::vector<std::array<double, 5>> slice_axes;
  std::string source;  ///< where it was read from
  /// An oblique table's radiance leaves out the beam's single scattering (a line on the surface,
  /// added in closed form by ObliqueModel). Tables that include it are refused as oblique ones.
  bool single_scattering_line_excluded = false;
  /// A slab's table (lucent fit --thickness-mm builds them): its thickness as d sigma_s' (the
  /// table's u and rho axes are per alpha', so the slab of every entry is d sigma_t' =
  /// slab_thickness_s / alpha'), and which side it tallies. Infinity: a semi-infinite sample.
  double slab_thickness_s = std::numeric_limits<double>::infinity();
  bool transmitted = false;  ///< the far side (transmittance) rather than the lit side
  bool slab() const { return slab_thickness_s < std::numeric_limits<double>::infinity(); }
};

/// Reads a table (finished or partial). Throws lucent::Error naming the file and the field.
TransportTable read_transport_table(const std::filesystem::path& path);
/// The same from a file's bytes (`source` names it in errors): the fuzz target's entry.
TransportTable parse_transport_table(const std::string& bytes, const std::string& source);
/// Writes atomically.
void write_transport_table(const TransportTable& table, const std::filesystem::path& path);

/// Merges partial tables (shards) into one finished table: every (slice, group) exactly once,
/// the same grid, seed and slices. Throws lucent::Error naming what does not match.
TransportTable merge_transport_tables(const std::vector<TransportTable>& partials);

/// Means and standard errors over the groups, far tails extrapolated where no photon arrived.
/// `groups` must hold every group of every slice.
void finish_transport_table(TransportTable& table, const std::vector<TransportTableGroup>& groups);

/// The table lucent ships (materials/tables/transport.lut, or $LUCENT_TRANSPORT_TABLE), read once.
const TransportTable& default_transport_table();
std::filesystem::path default_transport_table_path();
/// The oblique table lucent ships (materials/tables/oblique.lut, or $LUCENT_OBLIQUE_TABLE): the
/// slices the bundled captures need.
std::filesystem::path default_oblique_table_path();

}  // namespace lucent::materials
