// The transport table file written, tables merged, and the finishing of Monte Carlo group tallies
// (transport_table.h). Reading: transport_table_read.cpp.
#include "lucent/materials/transport_table.h"

#include "lucent/core/atomic_file.h"
#include "lucent/core/json_file.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "transport_table_format.h"

#ifndef LUCENT_TABLE_DIR
#define LUCENT_TABLE_DIR ""
#endif

namespace lucent::materials {
namespace {

using nlohmann::json;
// An entry is measured when its relative standard error is below this; beyond the last measured
// entry of a row the far tail is extrapolated (finish_transport_table).
constexpr double kMeasuredRelativeSe = 0.25;

static_assert(std::endian::native == std::endian::little, "the table payload is little-endian");

template <typename T>
void put(std::string& out, const T* data, std::size_t n) {
  out.append(reinterpret_cast<const char*>(data), n * sizeof(T));
}

json grid_json(const TransportTableGrid& g) {
  return {{"u", g.u},
          {"rho_min", g.rho_min},
          {"rho_max", g.rho_max},
          {"rho_per_decade", g.rho_per_decade},
          {"rho_bins", g.rho_bins()},
          {"phi_bins", g.phi_bins}};
}

json slice_json(double eta, double g, std::uint64_t photons, double incidence_deg,
                std::uint64_t white_photons) {
  json s = {{"eta", eta}, {"g", g}, {"photons", photons}};
  if (incidence_deg != 0) s["incidence_deg"] = incidence_deg;
  if (white_photons != 0 && white_photons != photons) s["white_photons"] = white_photons;
  return s;
}

// Fills the far tail of one row (fixed u) past its last measured bin, where too few photons
// arrived: log(v rho^(3/2)) continued linearly in rho from a weighted fit to the last measured
// bins (diffusion's far field, e^(-sigma_tr rho) / rho^(3/2) between the point-source and
// dipole forms), with the slope held <= 0.
void extrapolate_tail(const TransportTableGrid& grid, std::vector<double>& v,
                      std::vector<double>& rel_se, std::vector<bool>& extrapolated,
                      bool allow_empty) {
  const int J = grid.rho_bins();
  // The last bin measured to kMeasuredRelativeSe; a row too faint for that (the near-black nodes
  // at high g, with few photons) takes the threshold up until some bins qualify.
  int last = -1;
  double threshold = kMeasuredRelativeSe;
  for (; last < 0 && threshold < 10; threshold *= 2) {
    for (int j = 0; j < J; ++j)
      if (v[j] > 0 && rel_se[j] < threshold) last = j;
  }
  threshold /= 2;
  if (last < 0 && allow_empty) {
    // A slab's far side at an albedo and thickness that let nothing through (thick and dark):
    // a floor far below any capture's noise, every entry unsupported.
    for (int j = 0; j < J; ++j) v[j] = 1e-30, extrapolated[j] = true;
    return;
  }
  if (last < 0) throw Error("transport table: a row has no measured entry (too few photons)");
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  int used = 0;
  for (int j = last; j >= 0 && used < 8; --j) {
    if (!(v[j] > 0 && rel_se[j] < threshold)) continue;
    const double rho = grid.rho_centre(j);
    const double y = std::log(v[j]) + 1.5 * std::log(rho);
    const double w = 1.0 / std::max(1e-6, rel_se[j] * rel_se[j]);
    sw += w, sx += w * rho, sy += w * y, sxx += w * rho * rho, sxy += w * rho * y;
    ++used;
  }
  const double den = sw * sxx - sx * sx;
  double slope = used >= 2 && den > 0 ? (sw * sxy - sx * sy) / den : 0.0;
  slope = std::min(slope, 0.0);
  const double rho_l = grid.rho_centre(last);
  const double y_l = std::log(v[last]) + 1.5 * std::log(rho_l);
  for (int j = 0; j < J; ++j) {
    if (j <= last && v[j] > 0) continue;  // measured, or noisy inside the measured range: kept
    const double rho = grid.rho_centre(j);
    v[j] = std::exp(y_l + slope * (rho - rho_l) - 1.5 * std::log(rho));
    if (!(v[j] > 0)) v[j] = 1e-300;  // underflow far out: still positive, so logs stay finite
    rel_se[j] = INFINITY;
    extrapolated[j] = true;
  }
}

}  // namespace

const char* to_string(TableQuantity q) {
  return q == TableQuantity::kExitance ? "exitance" : "radiance";
}

int TransportTableGrid::rho_bins() const {
  return int(std::lround(std::log10(rho_max / rho_min) * rho_per_decade));
}
double TransportTableGrid::rho_edge(int j) const {
  return rho_min * std::pow(10.0, double(j) / rho_per_decade);
}
double TransportTableGrid::rho_centre(int j) const {
  return rho_min * std::pow(10.0, (j + 0.5) / rho_per_decade);
}

TransportTableGrid default_transport_grid() {
  TransportTableGrid g;
  // u = sqrt(1 - alpha'). Near u = 0 (alpha' -> 1: milk, cream, marble) the far field goes as
  // e^(-sqrt(3) u rho) (1 + sqrt(3) u rho) with rho up to 100, strongly curved in u, so the nodes
  // are 0.005 apart up to 0.02, then 0.01, 0.0125 up to 0.1; then 0.025 apart to 0.95. Near
  // black (alpha' < 0.1) the far field's decay rate changes fast with alpha' (with nodes 0.025
  // apart there the interpolant was 50-140% high at rho 1.5-3 for alpha' = 0.08, measured), so
  // 0.9625, 0.975, 0.9825, 0.99, 0.995 and 0.998 (alpha' 0.074 down to 0.004).
  for (double u : {0.0, 0.005, 0.01, 0.015, 0.02, 0.03, 0.04, 0.05, 0.0625, 0.075, 0.0875})
    g.u.push_back(u);
  for (int k = 4; k <= 38; ++k) g.u.push_back(0.025 * k);
  for (double u : {0.9625, 0.975, 0.9825, 0.99, 0.995, 0.998}) g.u.push_back(u);
  return g;
}

TransportTableGrid default_oblique_grid() {
  // Coarser in rho than the radial table (an oblique capture's fit starts beyond two pixels, rho
  // of ~1 for marble): 16 bins per decade from 0.05, deconvolved like the radial ones; 15-degree
  // wedges, where the asymmetry of a 45-degree beam changes by a few percent from one to the next.
  TransportTableGrid g = default_transport_grid();
  g.rho_min = 0.05;
  g.rho_per_decade = 16;
  g.phi_bins = 12;
  return g;
}

std::uint8_t encode_relative_se(double rel, bool extrapolated) {
  if (extrapolated || !std::isfinite(rel)) return kExtrapolatedEntry;
  const double code = std::round(200 + 40 * std::log10(std::max(rel, 1e-5)));
  return std::uint8_t(std::clamp(code, 0.0, 254.0));
}
double decode_relative_se(std::uint8_t code) {
  if (code == kExtrapolatedEntry) return INFINITY;
  return std::pow(10.0, (double(code) - 200) / 40);
}

void finish_transport_table(TransportTable& table, const std::vector<TransportTableGroup>& groups) {
  const std::size_t K = table.grid.u.size();
  const std::size_t rows = table.grid.rows();
  const int J = table.grid.rho_bins();
  const std::size_t n = rows * std::size_t(J);
  std::vector<std::vector<const TransportTableGroup*>> by_slice(table.slice_axes.size());
  for (const TransportTableGroup& g : groups) {
    if (g.slice < 0 || std::size_t(g.slice) >= by_slice.size())
      throw Error("transport table: group of an unknown slice");
    by_slice[std::size_t(g.slice)].push_back(&g);
  }
  table.slices.clear();
  for (std::size_t s = 0; s < by_slice.size(); ++s) {
    auto& list = by_slice[s];
    std::sort(list.begin(), list.end(), [](auto* a, auto* b) { return a->group < b->group; });
    if (int(list.size()) != table.groups)
      throw Error("transport table: slice " + std::to_string(s) + " has " +
                  std::to_string(list.size()) + " of its " + std::to_string(table.groups) +
                  " groups");
    for (int i = 0; i < table.groups; ++i)
      if (list[std::size_t(i)]->group != i)
        throw Error("transport table: slice " + std::to_string(s) + " lacks group " +
                    std::to_string(i) + " (or has it twice)");
    const double G = table.groups;
    TransportTableSlice slice;
    slice.eta = table.slice_axes[s][0];
    slice.g = table.slice_axes[s][1];
    slice.photons = std::uint64_t(table.slice_axes[s][2]);
    slice.incidence_deg = table.slice_axes[s][3];
    slice.white_photons = std::uint64_t(table.slice_axes[s][4]);
    for (int q = 0; q < kTableQuantities; ++q) {
      std::vector<double> mean(n, 0.0), rel(n, 0.0);
      for (std::size_t e = 0; e < n; ++e) {
        double sum = 0, sum2 = 0;
        for (const TransportTableGroup* g : list) {
          const double v = g->value[std::size_t(q)][e];
          sum += v;
          sum2 += v * v;
        }
        mean[e] = sum / G;
        const double var = std::max(0.0, (sum2 - sum * sum / G) / (G - 1));
        rel[e] = mean[e] > 0 ? std::sqrt(var / G) / mean[e] : INFINITY;
      }
      slice.value[std::size_t(q)].resize(n);
      slice.se_code[std::size_t(q)].resize(n);
      for (std::size_t k = 0; k < rows; ++k) {
        std::vector<double> v(mean.begin() + long(k * J), mean.begin() + long((k + 1) * J));
        std::vector<double> r(rel.begin() + long(k * J), rel.begin() + long((k + 1) * J));
        std::vector<bool> extrapolated(std::size_t(J), false);
        extrapolate_tail(table.grid, v, r, extrapolated, table.slab());
        for (int j = 0; j < J; ++j) {
          const std::size_t e = k * std::size_t(J) + std::size_t(j);
          slice.value[std::size_t(q)][e] = float(std::max(v[std::size_t(j)], 1e-37));
          slice.se_code[std::size_t(q)][e] =
              encode_relative_se(r[std::size_t(j)], extrapolated[std::size_t(j)]);
        }
      }
    }
    slice.total.resize(K);
    slice.total_se.resize(K);
    for (std::size_t k = 0; k < K; ++k) {
      double sum = 0, sum2 = 0;
      for (const TransportTableGroup* g : list) sum += g->total[k], sum2 += g->total[k] * g->total[k];
      slice.total[k] = sum / G;
      slice.total_se[k] = std::sqrt(std::max(0.0, (sum2 - sum * sum / G) / (G - 1)) / G);
    }
    table.slices.push_back(std::move(slice));
  }
  table.partial = false;
  table.partial_groups.clear();
  table.shard.clear();
}

void write_transport_table(const TransportTable& t, const std::filesystem::path& path) {
  const std::size_t K = t.grid.u.size();
  const std::size_t n = t.grid.entries();
  std::string payload;
  json slices = json::array();
  if (!t.partial) {
    for (const TransportTableSlice& s : t.slices) {
      slices.push_back(slice_json(s.eta, s.g, s.photons, s.incidence_deg, s.white_photons));
      for (int q = 0; q < kTableQuantities; ++q) {
        put(payload, s.value[std::size_t(q)].data(), n);
        put(payload, s.se_code[std::size_t(q)].data(), n);
      }
      put(payload, s.total.data(), K);
      put(payload, s.total_se.data(), K);
    }
  } else {
    for (const auto& a : t.slice_axes)
      slices.push_back(slice_json(a[0], a[1], std::uint64_t(a[2]), a[3], std::uint64_t(a[4])));
  }
  json groups = json::array();
  for (const TransportTableGroup& g : t.partial_groups) {
    groups.push_back({g.slice, g.group});
    for (int q = 0; q < kTableQuantities; ++q) put(payload, g.value[std::size_t(q)].data(), n);
    put(payload, g.total.data(), K);
  }
  json h = {
      {"format", detail::kTableFormat},
      {"version", detail::kTableVersion},
      {"kind", t.partial ? "partial" : "table"},
      {"description",
       t.grid.phi_bins > 1
           ? "2D profile of a semi-infinite slab under an oblique pencil beam travelling toward +x "
             "(bins in rho and in phi = atan2(|y|, x)), per unit power entering, white Monte "
             "Carlo (lucent tabulate)"
           : "radial profile of a semi-infinite slab under a normally incident pencil beam, per "
             "unit power entering, white Monte Carlo (lucent tabulate)"},
      {"units",
       {{"rho", "r sigma_t' (dimensionless)"},
        {"u", "sqrt(1 - alpha'), alpha' = sigma_s' / sigma_t'"},
        {"phi", "azimuth from the beam's direction of travel, [0, pi] in phi_bins wedges"},
        {"incidence_deg", "the beam's angle from the normal outside the medium, degrees"},
        {"exitance", "R(r) / sigma_t'^2: power per unit area leaving the surface, bin average"},
        {"radiance", "pi L(r, normal) / sigma_t'^2: pi times the radiance along the normal"},
        {"total", "total diffuse reflectance (whole plane), per unit power entering"}}},
      {"grid", grid_json(t.grid)},
      {"slices", slices},
      {"groups", t.groups},
      {"seed", t.seed},
      {"max_path", t.max_path},
      {"generator", t.generator},
      {"layout", t.partial
                     ? "per group: float64 exitance[u][phi][rho], radiance[u][phi][rho], total[u]"
                     : "per slice: for exitance then radiance float32 value[u][phi][rho], uint8 "
                       "se_code[u][phi][rho] (relative SE 10^((code-200)/40), 255 = extrapolated "
                       "tail); then float64 total[u], total_se[u]"},
      {"payload_bytes", payload.size()},
      {"crc32", crc32(0L, reinterpret_cast<const Bytef*>(payload.data()), uInt(payload.size()))}};
  if (t.partial) h["shard"] = t.shard, h["partial_groups"] = groups;
  if (t.single_scattering_line_excluded)
    h["radiance_single_scattering"] = "excluded: the beam's line y = 0, added in closed form";
  if (t.slab())
    h["slab"] = {{"thickness_s", t.slab_thickness_s},
                 {"side", t.transmitted ? "transmitted" : "reflected"},
                 {"units", "d sigma_s' (a node of alpha' a is a slab of d sigma_t' = thickness_s / "
                           "a); side: which surface is tallied; the unscattered beam is left out"}};
  write_file_atomically(path, h.dump() + "\n" + payload, /*binary=*/true);
}

TransportTable merge_transport_tables(const std::vector<TransportTable>& parts) {
  if (parts.empty()) throw Error("merge: no tables given");
  // Shards of one build are finished together; finished tables (other slices of the same grid,
  // e.g. other g values built with other photon counts) join slice by slice.
  TransportTable out;
  std::vector<TransportTableSlice> slices;
  const TransportTable* first_partial = nullptr;
  std::vector<TransportTableGroup> groups;
  for (const TransportTable& p : parts) {
    if (p.single_scattering_line_excluded != parts.front().single_scattering_line_excluded)
      throw Error(p.source + ": built by another lucent than " + parts.front().source +
                  " (radiance_single_scattering differs): rebuild one of them");
    if (!(p.grid == parts.front().grid) || p.groups != parts.front().groups)
      throw Error(p.source + ": grid or groups differ from " + parts.front().source +
                  "'s: tables of different grids cannot be merged");
    if (!p.partial) {
      slices.insert(slices.end(), p.slices.begin(), p.slices.end());
      continue;
    }
    if (!first_partial) first_partial = &p;
    if (p.seed != first_partial->seed || p.max_path != first_partial->max_path ||
        p.slice_axes != first_partial->slice_axes)
      throw Error(p.source + ": seed, max_path or slices differ from " + first_partial->source +
                  "'s: shards of different builds");
    groups.insert(groups.end(), p.partial_groups.begin(), p.partial_groups.end());
  }
  out = first_partial ? *first_partial : parts.front();
  out.partial_groups.clear();
  if (first_partial) {
    finish_transport_table(out, groups);
  } else {
    out.slices.clear();
  }
  out.slices.insert(out.slices.end(), slices.begin(), slices.end());
  const auto key = [](const TransportTableSlice& s) {
    return std::tuple(s.incidence_deg, s.g, s.eta);
  };
  std::sort(out.slices.begin(), out.slices.end(),
            [&](const auto& a, const auto& b) { return key(a) < key(b); });
  for (std::size_t i = 1; i < out.slices.size(); ++i)
    if (key(out.slices[i]) == key(out.slices[i - 1]))
      throw Error("merge: the slice eta=" + std::to_string(out.slices[i].eta) +
                  " g=" + std::to_string(out.slices[i].g) +
                  " incidence_deg=" + std::to_string(out.slices[i].incidence_deg) +
                  " is given twice");
  out.slice_axes.clear();
  for (const auto& s : out.slices)
    out.slice_axes.push_back(
        {s.eta, s.g, double(s.photons), s.incidence_deg, double(s.white_photons)});
  out.partial = false;
  out.shard.clear();
  out.source.clear();
  return out;
}

std::filesystem::path default_transport_table_path() {
  if (const char* env = std::getenv("LUCENT_TRANSPORT_TABLE"); env && *env) return env;
  return std::filesystem::path(LUCENT_TABLE_DIR) / "transport.lut";
}

std::filesystem::path default_oblique_table_path() {
  if (const char* env = std::getenv("LUCENT_OBLIQUE_TABLE"); env && *env) return env;
  return std::filesystem::path(LUCENT_TABLE_DIR) / "oblique.lut";
}

const TransportTable& default_transport_table() {
  static std::once_flag once;
  static TransportTable table;
  static std::string error;
  std::call_once(once, [] {
    try {
      table = read_transport_table(default_transport_table_path());
    } catch (const Error& e) {
      error = e.what();
    }
  });
  if (!error.empty()) throw Error(error);
  return table;
}

}  // namespace lucent::materials
