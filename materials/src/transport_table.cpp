// The transport table file and the finishing of Monte Carlo group tallies (transport_table.h).
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

#ifndef LUCENT_TABLE_DIR
#define LUCENT_TABLE_DIR ""
#endif

namespace lucent::materials {
namespace {

using nlohmann::json;
constexpr const char* kFormat = "lucent-transport-table";
constexpr int kVersion = 1;
// A header line longer than this is not ours (and would be read whole before the check).
constexpr std::size_t kMaxHeaderBytes = 1 << 20;
// The largest table lucent reads (the shipped radial one is 1.2 MB; a slice at a fine grid tens of
// MB): a mistaken multi-gigabyte file is refused by its size.
constexpr std::size_t kMaxTableBytes = std::size_t(512) << 20;
// An entry is measured when its relative standard error is below this; beyond the last measured
// entry of a row the far tail is extrapolated (finish_transport_table).
constexpr double kMeasuredRelativeSe = 0.25;

static_assert(std::endian::native == std::endian::little, "the table payload is little-endian");

template <typename T>
void put(std::string& out, const T* data, std::size_t n) {
  out.append(reinterpret_cast<const char*>(data), n * sizeof(T));
}

class PayloadReader {
 public:
  PayloadReader(const std::string& bytes, std::size_t offset, std::string source)
      : bytes_(bytes), offset_(offset), source_(std::move(source)) {}
  template <typename T>
  void get(T* data, std::size_t n, const char* what) {
    const std::size_t size = n * sizeof(T);
    if (bytes_.size() - offset_ < size)
      throw Error(source_ + ": payload ends early (in " + what + ")");
    std::memcpy(data, bytes_.data() + offset_, size);
    offset_ += size;
  }
  std::size_t left() const { return bytes_.size() - offset_; }

 private:
  const std::string& bytes_;
  std::size_t offset_;
  std::string source_;
};

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
      {"format", kFormat},
      {"version", kVersion},
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

namespace {

// A header's whole number as T, or a lucent::Error (nlohmann's get<int>() of 1e30 is undefined
// behaviour, of -1 as uint64 a wrap).
template <class T>
T whole_number(const json& v, const std::string& src, const char* name) {
  bool ok = v.is_number_integer();
  if (ok && v.is_number_unsigned()) {
    ok = v.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<T>::max());
  } else if (ok) {
    const std::int64_t i = v.get<std::int64_t>();
    ok = i >= static_cast<std::int64_t>(std::numeric_limits<T>::min()) &&
         (i < 0 || static_cast<std::uint64_t>(i) <=
                       static_cast<std::uint64_t>(std::numeric_limits<T>::max()));
  }
  if (!ok) throw Error(src + ": " + name + ": expected a whole number in range, found " + v.dump());
  return v.is_number_unsigned() ? static_cast<T>(v.get<std::uint64_t>())
                                : static_cast<T>(v.get<std::int64_t>());
}

TransportTable parse_unchecked(const std::string& file, const std::string& src);

}  // namespace

TransportTable parse_transport_table(const std::string& bytes, const std::string& source) {
  try {
    return parse_unchecked(bytes, source);
  } catch (const json::exception& e) {
    throw Error(source + ": not a valid lucent-transport-table header (" + std::string(e.what()) +
                ")");
  }
}

TransportTable read_transport_table(const std::filesystem::path& path) {
  // The bounded reading path (json_file.h): a regular file larger than the limit is refused by its
  // size before a byte is read, anything else stops at the limit.
  return parse_transport_table(read_input_file(path, kMaxTableBytes), path.string());
}

namespace {

TransportTable parse_unchecked(const std::string& file, const std::string& src) {
  const std::size_t newline = file.find('\n');
  if (newline == std::string::npos || newline > kMaxHeaderBytes)
    throw Error(src + ": not a lucent-transport-table (no header line)");
  const std::string header = file.substr(0, newline);
  json h;
  try {
    h = parse_json(header, src);
  } catch (const Error&) {
    throw Error(src + ": not a lucent-transport-table (the first line is not valid JSON)");
  }
  const auto field = [&](const char* name) -> const json& {
    if (!h.is_object() || !h.contains(name)) throw Error(src + ": missing field '" + name + "'");
    return h.at(name);
  };
  if (field("format") != kFormat) throw Error(src + ": format: expected \"lucent-transport-table\"");
  if (field("version") != kVersion) throw Error(src + ": version: expected 1");
  TransportTable t;
  t.source = src;
  try {
    const json& g = field("grid");
    t.grid.u = g.at("u").get<std::vector<double>>();
    t.grid.rho_min = g.at("rho_min").get<double>();
    t.grid.rho_max = g.at("rho_max").get<double>();
    t.grid.rho_per_decade = whole_number<int>(g.at("rho_per_decade"), src, "rho_per_decade");
    if (g.contains("phi_bins")) t.grid.phi_bins = whole_number<int>(g.at("phi_bins"), src, "phi_bins");
    t.groups = whole_number<int>(field("groups"), src, "groups");
    t.seed = whole_number<std::uint64_t>(field("seed"), src, "seed");
    t.max_path = field("max_path").get<double>();
    t.generator = field("generator").get<std::string>();
    t.partial = field("kind").get<std::string>() == "partial";
    t.single_scattering_line_excluded = h.contains("radiance_single_scattering");
    if (h.contains("slab")) {
      const json& slab = h.at("slab");
      t.slab_thickness_s = slab.at("thickness_s").get<double>();
      const std::string side = slab.at("side").get<std::string>();
      if (!(t.slab_thickness_s > 0 && t.slab_thickness_s < 1e9) ||
          (side != "reflected" && side != "transmitted"))
        throw Error(src + ": slab: expected thickness_s in (0, 1e9) and side reflected or "
                          "transmitted");
      t.transmitted = side == "transmitted";
    }
    for (const json& s : field("slices"))
      t.slice_axes.push_back({s.at("eta").get<double>(), s.at("g").get<double>(),
                              double(whole_number<std::uint64_t>(s.at("photons"), src, "photons")),
                              s.value("incidence_deg", 0.0),
                              s.contains("white_photons")
                                  ? double(whole_number<std::uint64_t>(s.at("white_photons"), src,
                                                                       "white_photons"))
                                  : 0.0});
  } catch (const json::exception& e) {
    throw Error(src + ": grid, slices or groups: unexpected value (" + std::string(e.what()) + ")");
  }
  // Every value checked before it sizes anything: a table is a document like any other, its
  // checksum says only that the bytes are the ones written.
  bool grid_ok = t.grid.u.size() >= 2 && t.grid.u.size() <= 4096 && t.grid.u.front() == 0 &&
                 std::isfinite(t.grid.rho_min) && std::isfinite(t.grid.rho_max) &&
                 t.grid.rho_min > 0 && t.grid.rho_max > t.grid.rho_min &&
                 t.grid.rho_max / t.grid.rho_min <= 1e12 && t.grid.rho_per_decade >= 1 &&
                 t.grid.rho_per_decade <= 200 && t.groups >= 2 && t.groups <= 1 << 20 &&
                 t.grid.phi_bins >= 1 && t.grid.phi_bins <= 360 && t.grid.rho_bins() >= 2 &&
                 std::isfinite(t.max_path) && t.max_path >= 0;
  for (std::size_t k = 1; grid_ok && k < t.grid.u.size(); ++k)
    grid_ok = t.grid.u[k] > t.grid.u[k - 1] && t.grid.u[k] < 1;
  if (!grid_ok)
    throw Error(src + ": grid: expected rising u nodes in [0, 1), a finite rho range of at least 2 "
                      "bins, 1..360 phi_bins, 2 or more groups and a finite max_path >= 0");
  if (t.slice_axes.empty()) throw Error(src + ": slices: expected at least one");
  for (const auto& a : t.slice_axes)
    if (!(a[0] >= 1 && a[0] <= 2.5 && a[1] >= 0 && a[1] < 1 && a[2] >= 1 && a[3] >= 0 &&
          a[3] < 90))
      throw Error(src + ": slices: eta in [1, 2.5], g in [0, 1), photons >= 1 and "
                  "incidence_deg in [0, 90) expected");

  const std::string_view payload_view(file.data() + newline + 1, file.size() - newline - 1);
  const std::string payload(payload_view);
  const std::uint64_t declared = whole_number<std::uint64_t>(field("payload_bytes"), src, "payload_bytes");
  if (payload.size() != declared)
    throw Error(src + ": payload_bytes: the header says " + std::to_string(declared) +
                " bytes, the file holds " + std::to_string(payload.size()));
  // What the header's grid and slices (or groups) take, against what is there, before any array
  // is sized from them.
  {
    const double n = double(t.grid.entries()), K = double(t.grid.u.size());
    double expected = 0;
    if (!t.partial) {
      expected = double(t.slice_axes.size()) *
                 (kTableQuantities * n * (sizeof(float) + sizeof(std::uint8_t)) + 2 * K * sizeof(double));
    } else {
      const json& groups = field("partial_groups");
      if (!groups.is_array()) throw Error(src + ": partial_groups: expected an array");
      expected = double(groups.size()) * (kTableQuantities * n + K) * sizeof(double);
    }
    if (expected != double(payload.size()))
      throw Error(src + ": payload_bytes: the grid and slices need " +
                  std::to_string(std::uint64_t(expected)) + " bytes, the file holds " +
                  std::to_string(payload.size()));
  }
  const std::uint64_t crc =
      crc32(0L, reinterpret_cast<const Bytef*>(payload.data()), uInt(payload.size()));
  if (crc != whole_number<std::uint64_t>(field("crc32"), src, "crc32"))
    throw Error(src + ": crc32: the payload is corrupt (checksum mismatch)");

  const std::size_t K = t.grid.u.size(), n = t.grid.entries();
  PayloadReader r(payload, 0, src);
  if (!t.partial) {
    for (const auto& a : t.slice_axes) {
      TransportTableSlice s;
      s.eta = a[0], s.g = a[1], s.photons = std::uint64_t(a[2]), s.incidence_deg = a[3];
      s.white_photons = std::uint64_t(a[4]);
      for (int q = 0; q < kTableQuantities; ++q) {
        s.value[std::size_t(q)].resize(n);
        s.se_code[std::size_t(q)].resize(n);
        r.get(s.value[std::size_t(q)].data(), n, "values");
        r.get(s.se_code[std::size_t(q)].data(), n, "standard errors");
        for (float v : s.value[std::size_t(q)])
          if (!(v > 0 && std::isfinite(v)))
            throw Error(src + ": values: expected finite positive entries");
      }
      s.total.resize(K), s.total_se.resize(K);
      r.get(s.total.data(), K, "totals");
      r.get(s.total_se.data(), K, "totals");
      for (std::size_t k = 0; k < K; ++k)
        if (!(s.total[k] >= 0 && s.total[k] <= 1 && s.total_se[k] >= 0 && std::isfinite(s.total_se[k])))
          throw Error(src + ": totals: expected total reflectances in [0, 1] with finite standard "
                            "errors >= 0");
      t.slices.push_back(std::move(s));
    }
  } else {
    t.shard = h.value("shard", "");
    for (const json& gj : field("partial_groups")) {
      TransportTableGroup g;
      g.slice = whole_number<int>(gj.at(0), src, "partial_groups"),
      g.group = whole_number<int>(gj.at(1), src, "partial_groups");
      if (g.slice < 0 || std::size_t(g.slice) >= t.slice_axes.size() || g.group < 0 ||
          g.group >= t.groups)
        throw Error(src + ": partial_groups: (slice, group) out of range");
      for (int q = 0; q < kTableQuantities; ++q) {
        g.value[std::size_t(q)].resize(n);
        r.get(g.value[std::size_t(q)].data(), n, "group values");
        for (double v : g.value[std::size_t(q)])
          if (!(v >= 0 && std::isfinite(v)))
            throw Error(src + ": group values: expected finite entries >= 0");
      }
      g.total.resize(K);
      r.get(g.total.data(), K, "group totals");
      for (double v : g.total)
        if (!(v >= 0 && v <= 1)) throw Error(src + ": group totals: expected values in [0, 1]");
      t.partial_groups.push_back(std::move(g));
    }
  }
  if (r.left() != 0) throw Error(src + ": payload: trailing bytes after the declared content");
  return t;
}

}  // namespace

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
