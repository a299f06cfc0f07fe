// A transport table file read and checked (transport_table.h): the header's fields, every value
// checked before it sizes anything, the payload's size and checksum, then the slices or a shard's
// groups. A table is a document like any other: its checksum says only that the bytes are the ones
// written.
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/materials/transport_table.h"
#include "transport_table_format.h"

namespace lucent::materials {
namespace {

using detail::kMaxHeaderBytes;
using detail::kMaxTableBytes;
using nlohmann::json;

static_assert(std::endian::native == std::endian::little, "the table payload is little-endian");

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

// The header's field `name`, or "SRC: missing field 'NAME'".
const json& header_field(const json& h, const char* name, const std::string& src) {
  if (!h.is_object() || !h.contains(name)) throw Error(src + ": missing field '" + name + "'");
  return h.at(name);
}

// Stage 1: the header's grid, slices, groups and provenance into a table without payload.
TransportTable read_header(const json& h, const std::string& src) {
  const auto field = [&](const char* name) -> const json& { return header_field(h, name, src); };
  TransportTable t;
  t.source = src;
  try {
    const json& g = field("grid");
    t.grid.u = g.at("u").get<std::vector<double>>();
    t.grid.rho_min = g.at("rho_min").get<double>();
    t.grid.rho_max = g.at("rho_max").get<double>();
    t.grid.rho_per_decade = whole_number<int>(g.at("rho_per_decade"), src, "rho_per_decade");
    if (g.contains("phi_bins"))
      t.grid.phi_bins = whole_number<int>(g.at("phi_bins"), src, "phi_bins");
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
        throw Error(src +
                    ": slab: expected thickness_s in (0, 1e9) and side reflected or "
                    "transmitted");
      t.transmitted = side == "transmitted";
    }
    for (const json& s : field("slices"))
      t.slice_axes.push_back(
          {s.at("eta").get<double>(), s.at("g").get<double>(),
           double(whole_number<std::uint64_t>(s.at("photons"), src, "photons")),
           s.value("incidence_deg", 0.0),
           s.contains("white_photons")
               ? double(whole_number<std::uint64_t>(s.at("white_photons"), src, "white_photons"))
               : 0.0});
  } catch (const json::exception& e) {
    throw Error(src + ": grid, slices or groups: unexpected value (" + std::string(e.what()) + ")");
  }
  return t;
}

// Stage 2: every value the header gives checked before it sizes anything: a table is a document
// like any other, its checksum says only that the bytes are the ones written.
void check_header(const TransportTable& t, const std::string& src) {
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
    throw Error(src +
                ": grid: expected rising u nodes in [0, 1), a finite rho range of at least 2 "
                "bins, 1..360 phi_bins, 2 or more groups and a finite max_path >= 0");
  if (t.slice_axes.empty()) throw Error(src + ": slices: expected at least one");
  for (const auto& a : t.slice_axes)
    if (!(a[0] >= 1 && a[0] <= 2.5 && a[1] >= 0 && a[1] < 1 && a[2] >= 1 && a[3] >= 0 && a[3] < 90))
      throw Error(src +
                  ": slices: eta in [1, 2.5], g in [0, 1), photons >= 1 and "
                  "incidence_deg in [0, 90) expected");
}

// Stage 3: the payload after the header line, its size against the header's payload_bytes and
// against what the grid and slices (or groups) take, and its checksum.
std::string checked_payload(const std::string& file, std::size_t newline, const json& h,
                            const TransportTable& t, const std::string& src) {
  const auto field = [&](const char* name) -> const json& { return header_field(h, name, src); };
  const std::string_view payload_view(file.data() + newline + 1, file.size() - newline - 1);
  const std::string payload(payload_view);
  const std::uint64_t declared =
      whole_number<std::uint64_t>(field("payload_bytes"), src, "payload_bytes");
  if (payload.size() != declared)
    throw Error(src + ": payload_bytes: the header says " + std::to_string(declared) +
                " bytes, the file holds " + std::to_string(payload.size()));
  // What the header's grid and slices (or groups) take, against what is there, before any array
  // is sized from them.
  {
    const double n = double(t.grid.entries()), K = double(t.grid.u.size());
    double expected = 0;
    if (!t.partial) {
      expected =
          double(t.slice_axes.size()) *
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

  return payload;
}

// Stage 4a: a finished table's slices: values, standard-error codes and totals per slice.
void read_slices(PayloadReader& r, TransportTable& t, const std::string& src) {
  const std::size_t K = t.grid.u.size(), n = t.grid.entries();
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
      if (!(s.total[k] >= 0 && s.total[k] <= 1 && s.total_se[k] >= 0 &&
            std::isfinite(s.total_se[k])))
        throw Error(src +
                    ": totals: expected total reflectances in [0, 1] with finite standard "
                    "errors >= 0");
    t.slices.push_back(std::move(s));
  }
}

// Stage 4b: a shard's groups: (slice, group), values and totals per group.
void read_groups(PayloadReader& r, const json& h, TransportTable& t, const std::string& src) {
  const auto field = [&](const char* name) -> const json& { return header_field(h, name, src); };
  const std::size_t K = t.grid.u.size(), n = t.grid.entries();
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
  if (header_field(h, "format", src) != detail::kTableFormat)
    throw Error(src + ": format: expected \"lucent-transport-table\"");
  if (header_field(h, "version", src) != detail::kTableVersion)
    throw Error(src + ": version: expected 1");
  TransportTable t = read_header(h, src);
  check_header(t, src);
  const std::string payload = checked_payload(file, newline, h, t, src);
  PayloadReader r(payload, 0, src);
  if (!t.partial) {
    read_slices(r, t, src);
  } else {
    read_groups(r, h, t, src);
  }
  if (r.left() != 0) throw Error(src + ": payload: trailing bytes after the declared content");
  return t;
}

}  // namespace

}  // namespace lucent::materials
