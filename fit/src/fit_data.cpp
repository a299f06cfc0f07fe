#include "lucent/fit/fit_data.h"

#include <charconv>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "lucent/acquire/profile.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"

namespace lucent::fit {
namespace {

std::string trim(std::string s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// %g: a user sees 1e+308, not a 309-digit number.
std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) out.push_back(trim(field));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// The key=value tokens of a CSV's leading comment lines.
using CommentFields = std::map<std::string, std::string>;

// Stage 1: the comment lines before the header. Leaves `line` holding the header line (empty when
// the text ends first) and `line_number` its number.
CommentFields read_comment_fields(std::istream& in, std::string& line, int& line_number) {
  CommentFields meta;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] != '#') break;
    std::stringstream tokens(t.substr(1));
    std::string token;
    while (tokens >> token) {
      const auto eq = token.find('=');
      if (eq != std::string::npos && eq > 0) meta[token.substr(0, eq)] = token.substr(eq + 1);
    }
  }
  return meta;
}

// Stage 2: each header column's index by name; every column named once, r_mm among them.
std::map<std::string, int> index_header_columns(const std::vector<std::string>& header,
                                                const std::string& source, int line_number) {
  std::map<std::string, int> column;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i].empty()) {
      throw Error(source + ": line " + std::to_string(line_number) + ": column " +
                  std::to_string(i + 1) + " of the header has no name");
    }
    if (!column.emplace(header[i], int(i)).second) {
      throw Error(source + ": line " + std::to_string(line_number) + ": column " + header[i] +
                  " appears twice in the header (which one is meant?)");
    }
  }
  if (column.count("r_mm") == 0) {
    throw Error(source + ": line " + std::to_string(line_number) +
                ": expected a header with r_mm and R (or R_r,R_g,R_b) columns");
  }
  return column;
}

// A numeric comment field, nullopt when absent. "1.5" or per channel "1.5,1.5,1.5" (lucent
// simulate): the channels must agree.
std::optional<double> comment_number(const CommentFields& meta, const std::string& key,
                                     const std::string& source) {
  const auto it = meta.find(key);
  if (it == meta.end()) return std::nullopt;
  const std::vector<std::string> parts = split(it->second);
  std::optional<double> value;
  for (const std::string& part : parts) {
    double v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc() || end != part.data() + part.size() || !std::isfinite(v))
      throw Error(source + ": comment field " + key + "=" + it->second + ": expected a number");
    if (value && std::abs(*value - v) > 1e-12)
      throw Error(source + ": comment field " + key + "=" + it->second +
                  ": the channels differ; lucent fit takes one value for all channels");
    value = v;
  }
  return value;
}

// Stage 3a: the comment fields of what was measured and how: the relative index, the quantity and
// its unit, calibration, the view direction and the pixel.
void apply_measurement_fields(const CommentFields& meta, const std::string& source,
                              ProfileData& d) {
  if (auto eta = comment_number(meta, "ior", source)) d.eta = *eta;
  if (auto eta = comment_number(meta, "eta", source)) {
    if (d.eta && std::abs(*d.eta - *eta) > 1e-9)
      throw Error(source + ": comment fields ior= and eta= disagree (" + meta.at("ior") + " and " +
                  meta.at("eta") + "): give one relative index");
    d.eta = *eta;
  }
  if (d.eta && !(*d.eta > 0 && *d.eta <= 4))
    throw Error(source + ": comment field ior/eta: expected a relative index in (0, 4]");
  if (auto it = meta.find("quantity"); it != meta.end()) {
    if (it->second == "radiance")
      d.exitance = false;
    else if (it->second != "exitance")
      throw Error(source + ": comment field quantity=" + it->second +
                  ": expected exitance or radiance");
  }
  if (auto it = meta.find("R_unit"); it != meta.end())
    d.per_incident_power = it->second.find("per_unit_incident_power") != std::string::npos;
  if (auto it = meta.find("calibrated"); it != meta.end()) {
    if (it->second != "true" && it->second != "false")
      throw Error(source + ": comment field calibrated=" + it->second + ": expected true or false");
    d.calibrated = it->second == "true";
  }
  if (auto view = comment_number(meta, "view_deg", source)) {
    if (!(*view >= 0 && *view < 90))
      throw Error(source + ": comment field view_deg: expected [0, 90) degrees");
    d.view_deg = *view;
  }
  if (auto pixel = comment_number(meta, "pixel_mm", source)) {
    if (!(*pixel >= 0 && *pixel < 1e3))
      throw Error(source + ": comment field pixel_mm: expected a pixel side in [0, 1000) mm");
    d.radial.pixel_mm = *pixel;
  }
}

// Stage 3b: the calibration's relative standard error per channel (calibration_relative_se=).
void apply_calibration_se_field(const CommentFields& meta, const std::string& source,
                                ProfileData& d) {
  if (auto it = meta.find("calibration_relative_se"); it != meta.end()) {
    const std::vector<std::string> parts = split(it->second);
    if (parts.size() != 3)
      throw Error(source + ": comment field calibration_relative_se=" + it->second +
                  ": expected three numbers (R,G,B) >= 0");
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      const auto [end, ec] = std::from_chars(parts[c].data(), parts[c].data() + parts[c].size(), v);
      if (ec != std::errc() || end != parts[c].data() + parts[c].size() || !(v >= 0 && v < 1))
        throw Error(source + ": comment field calibration_relative_se=" + it->second +
                    ": expected three numbers (R,G,B) in [0, 1)");
      d.calibration_relative_se[c] = v;
    }
  }
}

// Stage 3c: a slab's comment fields, thickness_mm= (inf: semi-infinite, as the simulator writes
// it) and side=reflected|transmitted.
void apply_slab_fields(const CommentFields& meta, const std::string& source, ProfileData& d) {
  // (The simulator writes an empty value or "inf" for a semi-infinite sample.)
  if (auto it = meta.find("thickness_mm");
      it != meta.end() && !it->second.empty() && it->second != "inf" && it->second != "infinite") {
    const auto thickness = comment_number(meta, "thickness_mm", source);
    if (!(*thickness > 0 && *thickness <= 1e4))
      throw Error(source + ": comment field thickness_mm=" + it->second +
                  ": expected a slab thickness in (0, 10000] mm, or inf");
    d.thickness_mm = thickness;
  }
  if (auto it = meta.find("side"); it != meta.end()) {
    if (it->second != "reflected" && it->second != "transmitted")
      throw Error(source + ": comment field side=" + it->second +
                  ": expected reflected (the lit side) or transmitted (the far side)");
    d.transmitted = it->second == "transmitted";
    if (d.transmitted && !d.thickness_mm)
      throw Error(source + ": comment field side=transmitted: the far side needs thickness_mm=");
  }
}

// Stage 3d: the white reference's system response (acquire): rms radius and the radial profile.
void apply_system_response_fields(const CommentFields& meta, const std::string& source,
                                  ProfileData& d) {
  if (auto it = meta.find("system_response_r_mm"); it != meta.end()) {
    const auto list = [&](const std::string& key) {
      std::vector<double> out;
      const auto found = meta.find(key);
      if (found == meta.end())
        throw Error(source + ": comment field system_response_r_mm= needs system_response=");
      for (const std::string& part : split(found->second)) {
        double v = 0;
        const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
        if (ec != std::errc() || end != part.data() + part.size() || !std::isfinite(v))
          throw Error(source + ": comment field " + key + ": expected finite numbers");
        out.push_back(v);
      }
      return out;
    };
    d.response_r_mm = list("system_response_r_mm");
    d.response_value = list("system_response");
    if (d.response_r_mm.size() != d.response_value.size() || d.response_r_mm.size() < 2)
      throw Error(source + ": comment fields system_response_r_mm= and system_response=: "
                           "expected as many radii as values, at least 2");
    for (std::size_t i = 1; i < d.response_r_mm.size(); ++i)
      if (!(d.response_r_mm[i] > d.response_r_mm[i - 1]) || d.response_r_mm[0] < 0)
        throw Error(source + ": comment field system_response_r_mm=: expected radii >= 0, rising");
    if (auto rms = comment_number(meta, "system_response_rms_mm", source)) {
      if (!(*rms >= 0)) throw Error(source + ": comment field system_response_rms_mm: expected >= 0");
      d.response_rms_mm = *rms;
    }
  }
}

// Stage 3: every comment field into `d`, checked in this order (the first error found is the one
// reported).
void apply_comment_fields(const CommentFields& meta, const std::string& source, ProfileData& d) {
  apply_measurement_fields(meta, source, d);
  apply_calibration_se_field(meta, source, d);
  apply_slab_fields(meta, source, d);
  apply_system_response_fields(meta, source, d);
  if (auto incidence = comment_number(meta, "incidence_deg", source)) {
    if (!(*incidence >= 0 && *incidence < 90))
      throw Error(source + ": comment field incidence_deg: expected [0, 90) degrees");
    d.incidence_polar_deg = *incidence;
  }
}

// Each channel's value and standard-error column index (-1: none).
struct ValueColumns {
  std::array<int, 3> value{-1, -1, -1}, standard_error{-1, -1, -1};
};

// Stage 4: the value and standard-error columns of each channel, and so which channels carry data.
ValueColumns find_value_columns(const std::map<std::string, int>& column, const std::string& source,
                                int line_number, ProfileData& d) {
  const auto has = [&](const std::string& name) { return column.count(name) > 0; };
  std::array<int, 3> value_col{-1, -1, -1}, se_col{-1, -1, -1};
  const char* suffix[3] = {"_r", "_g", "_b"};
  if (has("R")) {
    value_col = {column.at("R"), column.at("R"), column.at("R")};
    if (has("se")) se_col = {column.at("se"), column.at("se"), column.at("se")};
    d.channels = {true, false, false};
  } else {
    for (int c = 0; c < 3; ++c) {
      const std::string name = std::string("R") + suffix[c];
      if (has(name)) value_col[c] = column.at(name);
      if (has(std::string("se") + suffix[c])) se_col[c] = column.at(std::string("se") + suffix[c]);
      d.channels[c] = value_col[c] >= 0;
    }
    if (!d.channels[0] && !d.channels[1] && !d.channels[2]) {
      throw Error(source + ": line " + std::to_string(line_number) +
                  ": expected value columns R or R_r,R_g,R_b beside r_mm");
    }
  }
  return {value_col, se_col};
}

// What reading the rows leaves to note: whether errors were assumed, and per channel the bins
// with a zero standard error.
struct RowTally {
  bool assumed_errors = false;
  std::array<int, 3> zero_se{};
};

// Stage 5: the data rows after the header (at `line_number`) into d.radial, checked field by
// field.
RowTally read_profile_rows(std::istream& in, int line_number,
                           const std::vector<std::string>& header,
                           const std::map<std::string, int>& column, const ValueColumns& columns,
                           const std::string& source, ProfileData& d) {
  const std::array<int, 3>& value_col = columns.value;
  const std::array<int, 3>& se_col = columns.standard_error;
  const int inner = column.count("r_inner_mm") > 0 ? column.at("r_inner_mm") : -1;
  const int outer = column.count("r_outer_mm") > 0 ? column.at("r_outer_mm") : -1;
  RowTally tally;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    const std::vector<std::string> f = split(trim(line));
    const std::string where = source + ": line " + std::to_string(line_number) + ": ";
    if (f.size() != header.size()) {
      throw Error(where + "expected " + std::to_string(header.size()) + " fields, found " +
                  std::to_string(f.size()));
    }
    const auto number = [&](int col) {
      double v = 0;
      const std::string& t = f[col];
      const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v)) {
        throw Error(where + "column " + header[col] + ": expected a finite number, got '" + t +
                    "'");
      }
      return v;
    };
    const double r = number(column.at("r_mm"));
    if (r < 0) throw Error(where + "r_mm must be >= 0");
    std::array<double, 3> v{}, se{};
    for (int c = 0; c < 3; ++c) {
      v[c] = value_col[c] >= 0 ? number(value_col[c]) : 0.0;
      if (se_col[c] >= 0) {
        se[c] = number(se_col[c]);
        if (se[c] < 0)
          throw Error(where + "column " + header[se_col[c]] + ": expected a standard error >= 0");
        // 0: a Monte Carlo bin no photon reached (value 0 too): kept out of the fit (the fit
        // uses only samples with a standard error > 0), counted.
        if (se[c] == 0 && d.channels[c]) ++tally.zero_se[c];
      } else {
        se[c] = 0.05 * std::abs(v[c]);  // documented assumption: 5% relative error
        tally.assumed_errors = true;
      }
    }
    const double r_inner = inner >= 0 ? number(inner) : r;
    const double r_outer = outer >= 0 ? number(outer) : r;
    if (!(r_inner >= 0 && r_inner <= r && r <= r_outer)) {
      throw Error(where + "expected 0 <= r_inner_mm <= r_mm <= r_outer_mm, got " +
                  format_number(r_inner) + ", " + format_number(r) + ", " +
                  format_number(r_outer));
    }
    // Rows in order of radius, each once: a duplicated row would double its weight in silence.
    if (!d.radial.r_mm.empty() && !(r > d.radial.r_mm.back()))
      throw Error(where + "r_mm " + format_number(r) + " is not above the previous row's " +
                  format_number(d.radial.r_mm.back()) +
                  " (rows must rise in radius, each radius once)");
    d.radial.r_mm.push_back(r);
    d.radial.r_inner_mm.push_back(r_inner);
    d.radial.r_outer_mm.push_back(r_outer);
    for (int c = 0; c < 3; ++c) {
      d.radial.value[c].push_back(v[c]);
      d.radial.standard_error[c].push_back(se[c]);
    }
  }
  return tally;
}

// Stage 6: notes on assumed errors and skipped bins; a channel with no data at all is dropped.
void note_skipped_data(const RowTally& tally, const std::string& source, ProfileData& d) {
  const std::array<int, 3>& zero_se = tally.zero_se;
  if (tally.assumed_errors)
    d.notes.push_back(source + ": no standard-error columns; 5% relative errors assumed");
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    if (!d.channels[c] || zero_se[c] == 0) continue;
    if (zero_se[c] == int(d.radial.size())) {
      // No bin holds light: a channel that does not scatter (the wine's green and blue). Not
      // fitted; the material gets no scattering there.
      d.channels[c] = false;
      d.notes.push_back(source + ": channel " + names[c] +
                        " holds no data (every standard error is 0): not fitted");
    } else {
      d.notes.push_back(source + ": channel " + names[c] + ": " + std::to_string(zero_se[c]) +
                        " bins with a zero standard error (no data) skipped");
    }
  }
}

}  // namespace

ProfileData parse_profile_csv(std::string_view text, const std::string& source) {
  std::istringstream in{std::string(text)};
  std::string line;
  int line_number = 0;
  const CommentFields meta = read_comment_fields(in, line, line_number);
  const std::vector<std::string> header = split(trim(line));
  const std::map<std::string, int> column = index_header_columns(header, source, line_number);
  ProfileData d;
  d.source = source;
  d.exitance = true;  // CSV values are per mm^2 per unit power entering the sample
  d.per_incident_power = false;
  apply_comment_fields(meta, source, d);
  const ValueColumns columns = find_value_columns(column, source, line_number, d);
  const RowTally tally = read_profile_rows(in, line_number, header, column, columns, source, d);
  note_skipped_data(tally, source, d);
  if (d.radial.size() == 0) throw Error(source + ": the profile is empty (a header and no rows)");
  return d;
}

ProfileData profile_data_from_json(const nlohmann::json& doc, const std::string& source) {
  const acquire::Profile p = acquire::profile_from_json(doc, source);
  ProfileData d;
  d.source = source;
  d.calibrated = p.calibrated;
  if (p.beam_power && p.provenance.contains("white_reference")) {
    const auto& white = p.provenance["white_reference"];
    if (white.is_object() && white.contains("beam_power_standard_error") &&
        white["beam_power_standard_error"].is_array() &&
        white["beam_power_standard_error"].size() == 3) {
      for (int c = 0; c < 3; ++c) {
        const auto& se = white["beam_power_standard_error"][c];
        if (se.is_number() && (*p.beam_power)[c] > 0) {
          d.calibration_relative_se[c] = se.get<double>() / (*p.beam_power)[c];
        }
      }
    }
  }
  d.eta = p.ior;
  d.thickness_mm = p.thickness_mm;
  d.transmitted = p.transmitted;
  d.response_r_mm = p.response_r_mm;
  d.response_value = p.response_value;
  d.response_rms_mm = p.response_rms_mm;
  d.incidence_polar_deg = p.incidence_polar_deg;
  d.incidence_azimuth_deg = p.incidence_azimuth_deg;
  d.view_deg = p.view_deg;
  d.radial.r_mm = p.radial.r_mm;
  d.radial.pixel_mm = p.pixel_pitch_mm;
  d.radial.r_inner_mm = p.radial.r_inner_mm;
  d.radial.r_outer_mm = p.radial.r_outer_mm;
  for (int c = 0; c < 3; ++c) {
    d.radial.value[c] = p.radial.value[c];
    d.radial.standard_error[c] = p.radial.standard_error[c];
  }
  if (p.samples_2d) {
    Samples2d s;
    s.x_mm = p.samples_2d->x_mm;
    s.y_mm = p.samples_2d->y_mm;
    s.pixel_mm = p.pixel_pitch_mm;
    for (int c = 0; c < 3; ++c) {
      s.value[c] = p.samples_2d->value[c];
      s.standard_error[c] = p.samples_2d->standard_error[c];
    }
    d.samples_2d = s;
  }
  return d;
}

ProfileData load_profile_data(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".csv") {
    std::string text = read_input_file(path);
    if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // a UTF-8 byte order mark
    return parse_profile_csv(text, path.string());
  }
  if (ext == ".json") return profile_data_from_json(read_json_file(path), path.string());
  throw Error(path.string() + ": expected a lucent-profile .json (from lucent acquire) or a .csv");
}

}  // namespace lucent::fit
