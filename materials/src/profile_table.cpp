#include "lucent/materials/profile_table.h"

#include <charconv>
#include <cmath>
#include <istream>
#include <numbers>
#include <sstream>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/quadrature.h"
#include "lucent/materials/radial_slices.h"
#include "lucent/materials/tabulated.h"

namespace lucent::materials {
namespace {

constexpr const char* kConfigColumns[15] = {"xi_x", "xi_y", "xi_z", "ni_x", "ni_y",
                                            "ni_z", "wi_x", "wi_y", "wi_z", "xo_x",
                                            "xo_y", "xo_z", "no_x", "no_y", "no_z"};

std::string trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(first, last - first + 1));
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, separator)) fields.push_back(trim(field));
  if (!line.empty() && line.back() == separator) fields.emplace_back();
  return fields;
}

bool parse_double(const std::string& text, double& value) {
  if (text.empty()) return false;
  const char* begin = text.data();
  if (*begin == '+') ++begin;
  const auto [end, error] = std::from_chars(begin, text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && std::isfinite(value);
}

// Inputs echoed back (radii, positions): the shortest text that reads back to the same double.
std::string format_input(double v) {
  char buffer[64];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, v);
  (void)error;
  return std::string(buffer, end);
}

// Model values: 17 significant digits.
std::string format_number(double v) {
  char buffer[64];
  const auto [end, error] =
      std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, 17);
  (void)error;  // 64 characters always suffice for 17 significant digits
  return std::string(buffer, end);
}

Vec3<double> plane_normal() {
  return {0.0, 0.0, 1.0};
}

}  // namespace

DiffusionModel parse_diffusion_model(const std::string& name, const std::string& option,
                                     bool allow_tabulated) {
  if (name == "dipole") return DiffusionModel::kDipole;
  if (name == "ddipole") return DiffusionModel::kDirectionalDipole;
  if (name == "tabulated" && allow_tabulated) return DiffusionModel::kTabulated;
  if (name == "tabulated")
    throw Error(option + ": 'tabulated' is radial only (normal incidence on a plane); expected "
                         "'dipole' or 'ddipole' here");
  throw Error(option + ": expected 'dipole', 'ddipole'" +
              std::string(allow_tabulated ? " or 'tabulated'" : "") + ", got '" + name + "'");
}

std::string to_string(DiffusionModel model) {
  return model == DiffusionModel::kDipole              ? "dipole"
         : model == DiffusionModel::kDirectionalDipole ? "ddipole"
                                                       : "tabulated";
}

DiffusionModel preferred_model(const Material& material) {
  const std::string fitted = material.diffusion_model("");
  if (!fitted.empty() && fitted != "tabulated") return parse_diffusion_model(fitted, "model", true);
  // A tabulated fit renders tabulated where a table serves its (g, eta) here (the shipped one, or
  // the slice its fit built and cached), else with its cheapest adequate model.
  try {
    for (int c = 0; c < 3; ++c) {
      radial_profile_value(material, c, DiffusionModel::kTabulated, TableQuantity::kRadiance, 1.0);
    }
    return DiffusionModel::kTabulated;
  } catch (const Error&) {
    // The fit's fallback (its adequate model, or the closest when none is adequate); files written
    // before fallback_model existed name the closest one in adequate_model.
    if (fitted == "tabulated" && !material.fallback_model.empty())
      return parse_diffusion_model(material.fallback_model, "fallback_model", false);
    if (fitted == "tabulated" && !material.adequate_model.empty() &&
        material.adequate_model != "none")
      return parse_diffusion_model(material.adequate_model, "adequate_model", false);
    return DiffusionModel::kDirectionalDipole;  // eta or g outside the table
  }
}

std::vector<double> parse_radius_list(const std::string& text, const std::string& option) {
  std::vector<double> radii;
  for (const std::string& field : split(text, ',')) {
    double r = 0.0;
    if (!parse_double(field, r)) {
      throw Error(option + ": expected a comma-separated list of radii in mm, got '" + field + "'");
    }
    if (!(r >= 0.0 && r <= 1e6))
      throw Error(option + ": radius " + field + " mm: expected a radius in [0, 1e6] mm");
    radii.push_back(r);
  }
  if (radii.empty()) throw Error(option + ": expected at least one radius in mm");
  return radii;
}

std::vector<double> parse_radius_range(const std::string& text, const std::string& option) {
  const std::vector<std::string> parts = split(text, ':');
  const std::string expected =
      option + ": expected FROM:TO:COUNT[:lin|log] in mm, got '" + text + "'";
  if (parts.size() != 3 && parts.size() != 4) throw Error(expected);
  double from = 0.0, to = 0.0, count_value = 0.0;
  if (!parse_double(parts[0], from) || !parse_double(parts[1], to) ||
      !parse_double(parts[2], count_value)) {
    throw Error(expected);
  }
  const std::string spacing = parts.size() == 4 ? parts[3] : "lin";
  if (spacing != "lin" && spacing != "log") throw Error(expected);
  if (from < 0.0 || to < from || to > 1e6) {
    throw Error(option + ": expected 0 <= FROM <= TO <= 1e6 (mm), got FROM=" + parts[0] +
                " TO=" + parts[1]);
  }
  if (count_value < 1.0 || count_value > 1e7 || std::floor(count_value) != count_value) {
    throw Error(option + ": COUNT must be a whole number from 1 to 10^7, got " + parts[2]);
  }
  if (spacing == "log" && from <= 0.0) {
    throw Error(option + ": log spacing needs FROM > 0 mm, got " + parts[0]);
  }
  const auto count = static_cast<std::size_t>(count_value);
  std::vector<double> radii(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double t = count == 1 ? 0.0 : static_cast<double>(i) / static_cast<double>(count - 1);
    radii[i] = spacing == "log" ? from * std::pow(to / from, t) : from + (to - from) * t;
  }
  radii.back() = to;  // exact end point despite rounding
  return radii;
}

std::array<double, 3> evaluate_bssrdf(const Material& material, DiffusionModel model,
                                      const BssrdfConfig& c) {
  if (model == DiffusionModel::kTabulated)
    throw Error("--configs: the tabulated model is radial only (normal incidence on a plane); "
                "use --r or --r-range");
  std::array<double, 3> S{};
  for (int channel = 0; channel < 3; ++channel) {
    const Medium<double> medium = material.medium(channel);
    if (model == DiffusionModel::kDipole) {
      S[channel] = StandardDipole<double>(medium).S_d((c.x_o - c.x_i).norm());
    } else {
      S[channel] = DirectionalDipole<double>(medium).S_d(c.x_i, c.n_i, c.w_i, c.x_o, c.n_o);
    }
  }
  return S;
}

double radial_profile_value(const Material& material, int channel, DiffusionModel model,
                            TableQuantity quantity, double r) {
  const Medium<double> medium = material.medium(channel);
  const bool radiance = quantity == TableQuantity::kRadiance;
  switch (model) {
    case DiffusionModel::kDipole: {
      const double v = StandardDipole<double>(medium).R_d(r);
      return radiance ? v * fresnel_transmittance(1.0, medium.eta) : v;
    }
    case DiffusionModel::kDirectionalDipole: {
      const DirectionalDipole<double> ddipole(medium);
      const double pi_s = std::numbers::pi * ddipole.S_d(Vec3<double>::Zero(), plane_normal(),
                                                         plane_normal(), Vec3<double>(r, 0.0, 0.0),
                                                         plane_normal());
      return pi_s * (radiance ? fresnel_transmittance(1.0, medium.eta)
                              : medium.eta * medium.eta *
                                    (1 - diffuse_fresnel_reflectance(medium.eta)));
    }
    case DiffusionModel::kTabulated: {
      // Materials with sigma_s and g carry their own g per channel.
      return TabulatedModel<double>(*radial_profile_for(medium.g, medium.eta), medium)
          .at(quantity, r);
    }
  }
  return 0.0;
}

std::string radial_profile_csv(const Material& material, const RadialProfileOptions& options) {
  std::ostringstream out;
  out << "# format=lucent-radial-profile version=1 quantity=" << to_string(options.quantity)
      << " ior=" << format_input(material.ior) << " model=" << to_string(options.model)
      << " incidence_deg=0 units=mm^-2_per_unit_power_entering material=" << material.name
      << "\n";
  std::ostringstream rows;
  rows << "r_mm,R_r,R_g,R_b\n";
  for (double r : options.r_mm) {
    rows << format_input(r);
    for (int channel = 0; channel < 3; ++channel)
      rows << ',' << format_number(radial_profile_value(material, channel, options.model,
                                                        options.quantity, r));
    rows << '\n';
  }
  if (options.total) {
    out << "# total=";
    for (int channel = 0; channel < 3; ++channel)
      out << (channel ? "," : "")
          << format_number(total_diffuse_reflectance(material, channel, options.model));
    out << '\n';
  }
  return out.str() + rows.str();
}

double total_diffuse_reflectance(const Material& material, int channel, DiffusionModel model) {
  const Medium<double> medium = material.medium(channel);
  if (model == DiffusionModel::kDipole)
    return StandardDipole<double>(medium).total_diffuse_reflectance();
  if (model == DiffusionModel::kTabulated) {
    // The value at 1 mm checks the table covers the medium (a clear error when it does not).
    radial_profile_value(material, channel, model, TableQuantity::kExitance, 1.0);
    return TabulatedModel<double>(*radial_profile_for(medium.g, medium.eta), medium)
        .total_diffuse_reflectance();
  }
  const auto c = derive_coefficients(medium);
  if (!c.scatters()) return 0.0;
  return integrate_over_plane(
      [&](double r) {
        return radial_profile_value(material, channel, model, TableQuantity::kExitance, r);
      },
      c.z_r, 1e-9);
}

std::vector<BssrdfConfig> read_bssrdf_configs(std::istream& in, const std::string& source) {
  std::string line;
  int line_number = 0;
  // Header: the 15 named columns in order.
  while (std::getline(in, line)) {
    ++line_number;
    if (!trim(line).empty()) break;
  }
  const std::vector<std::string> header = split(trim(line), ',');
  bool header_ok = header.size() == 15;
  for (std::size_t i = 0; header_ok && i < 15; ++i) header_ok = header[i] == kConfigColumns[i];
  if (!header_ok) {
    throw Error(source + ": line " + std::to_string(line_number) +
                ": expected the header xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,"
                "xo_x,xo_y,xo_z,no_x,no_y,no_z");
  }
  std::vector<BssrdfConfig> configs;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty()) continue;
    const std::vector<std::string> fields = split(trim(line), ',');
    const std::string where = source + ": line " + std::to_string(line_number) + ": ";
    if (fields.size() != 15) {
      throw Error(where + "expected 15 comma-separated numbers, found " +
                  std::to_string(fields.size()) + " fields");
    }
    double v[15];
    for (int i = 0; i < 15; ++i) {
      if (!parse_double(fields[i], v[i])) {
        throw Error(where + "column " + kConfigColumns[i] + ": expected a finite number, got '" +
                    fields[i] + "'");
      }
    }
    BssrdfConfig c{{v[0], v[1], v[2]},
                   {v[3], v[4], v[5]},
                   {v[6], v[7], v[8]},
                   {v[9], v[10], v[11]},
                   {v[12], v[13], v[14]}};
    const std::pair<const Vec3<double>*, const char*> units[] = {
        {&c.n_i, "ni"}, {&c.w_i, "wi"}, {&c.n_o, "no"}};
    for (const auto& [vector, name] : units) {
      const double length = vector->norm();
      if (std::abs(length - 1.0) > 1e-6) {
        throw Error(where + name + " must be a unit vector (length 1 to 1e-6), its length is " +
                    format_number(length));
      }
    }
    configs.push_back(c);
  }
  if (configs.empty()) throw Error(source + ": expected at least one configuration row");
  return configs;
}

std::string bssrdf_configs_csv(const Material& material, DiffusionModel model,
                               const std::vector<BssrdfConfig>& configs) {
  std::ostringstream out;
  for (const char* column : kConfigColumns) out << column << ',';
  out << "Sd_r,Sd_g,Sd_b\n";
  for (const BssrdfConfig& c : configs) {
    for (const Vec3<double>* v : {&c.x_i, &c.n_i, &c.w_i, &c.x_o, &c.n_o}) {
      for (int k = 0; k < 3; ++k) out << format_input((*v)[k]) << ',';
    }
    const std::array<double, 3> S = evaluate_bssrdf(material, model, c);
    out << format_number(S[0]) << ',' << format_number(S[1]) << ',' << format_number(S[2]) << '\n';
  }
  return out.str();
}

}  // namespace lucent::materials
