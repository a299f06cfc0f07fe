// The photon transport's options and results as data (photon_transport.h): the radial bins,
// option validation and the exitance CSV. The transport itself is photon_transport.cpp.
#include "lucent/acquire/photon_transport.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "lucent/core/error.h"

namespace lucent::acquire {
namespace {

constexpr int kFineBins = 50;
constexpr double kFineBinWidthMm = 0.01;
constexpr double kBinGrowth = 1.05;
// More photons than anyone can wait for; keeps every photon count of three channels in 64 bits.
constexpr std::uint64_t kMaxPhotons = 1'000'000'000'000'000;

[[noreturn]] void bad_option(const std::string& name, const std::string& expected, double got) {
  std::ostringstream s;
  s.precision(6);
  s << "photon transport: option '" << name << "' must be " << expected << " (got " << got << ")";
  throw Error(s.str());
}

// No NaN or Inf ever goes into a file: a channel that was not simulated leaves its fields empty.
std::string format_number(double value) {
  if (!std::isfinite(value)) return "";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace

std::vector<ExitanceBin> exitance_bins(double max_radius_mm) {
  if (!(max_radius_mm > 0) || !std::isfinite(max_radius_mm)) {
    bad_option("max_radius_mm", "> 0 and finite", max_radius_mm);
  }
  // Width of bin k: 0.01 mm for k < 50 (up to 0.5 mm), then 5% wider per bin.
  auto width = [](int k) {
    return k < kFineBins ? kFineBinWidthMm
                         : kFineBinWidthMm * std::pow(kBinGrowth, k - kFineBins + 1);
  };
  std::vector<double> edges{0.0};
  for (int k = 0;; ++k) {
    const double next = k < kFineBins ? (k + 1) * kFineBinWidthMm : edges.back() + width(k);
    if (next >= max_radius_mm || max_radius_mm - next < 0.5 * width(k + 1)) {
      edges.push_back(max_radius_mm);
      break;
    }
    edges.push_back(next);
  }
  std::vector<ExitanceBin> bins(edges.size() - 1);
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const double ri = edges[b], ro = edges[b + 1];
    bins[b].r_inner_mm = ri;
    bins[b].r_outer_mm = ro;
    bins[b].r_centre_mm = 2.0 / 3.0 * (ro * ro * ro - ri * ri * ri) / (ro * ro - ri * ri);
  }
  return bins;
}

void validate_photon_transport_options(const PhotonTransportOptions& o) {
  // Fewer than 100 photons give no usable standard error (every tally bin holds 0 or 1 photon).
  if (o.photons < 100 || o.photons > kMaxPhotons) {
    bad_option("photons", "in [100, 1e15] per channel", static_cast<double>(o.photons));
  }
  if (o.threads > 1024) bad_option("threads", "at most 1024 (0: all cores)", o.threads);
  if (!(o.thickness_mm > 0))
    bad_option("thickness_mm", "> 0 (infinity: semi-infinite)", o.thickness_mm);
  if (!(o.beam_sigma_mm >= 0 && o.beam_sigma_mm <= 100))
    bad_option("beam_sigma_mm", "in [0, 100] mm (0: a pencil beam)", o.beam_sigma_mm);
  if (o.far_side && !std::isfinite(o.thickness_mm))
    throw Error("side: the far side (transmitted) needs a finite thickness_mm");
  if (!(o.incidence_deg >= 0 && o.incidence_deg < 90)) {
    bad_option("incidence_deg", "in [0, 90)", o.incidence_deg);
  }
  if (!std::isfinite(o.azimuth_deg)) bad_option("azimuth_deg", "finite", o.azimuth_deg);
  if (o.threads < 0) bad_option("threads", ">= 0 (0: all cores)", o.threads);
  if (!(o.max_radius_mm > 0) || !std::isfinite(o.max_radius_mm)) {
    bad_option("max_radius_mm", "> 0 and finite", o.max_radius_mm);
  }
  if (o.image) {
    if (o.size < 1 || o.size > 16384) bad_option("size", "in [1, 16384]", o.size);
    if (!(o.pixel_mm > 0) || !std::isfinite(o.pixel_mm)) {
      bad_option("pixel_mm", "> 0 and finite", o.pixel_mm);
    }
    if (!(o.view_deg >= 0 && o.view_deg < 90)) bad_option("view_deg", "in [0, 90)", o.view_deg);
    if (!std::isfinite(o.view_azimuth_deg)) {
      bad_option("view_azimuth_deg", "finite", o.view_azimuth_deg);
    }
  }
  if (!(o.channels[0] || o.channels[1] || o.channels[2])) {
    throw Error("photon transport: option 'channels' must select at least one channel");
  }
  for (int c = 0; c < 3; ++c) {
    if (!o.channels[static_cast<std::size_t>(c)]) continue;
    const auto& m = o.media[static_cast<std::size_t>(c)];
    const std::string prefix = "media[" + std::to_string(c) + "].";
    if (!(m.sigma_a >= 0) || !std::isfinite(m.sigma_a)) {
      bad_option(prefix + "sigma_a", ">= 0 and finite (mm^-1)", m.sigma_a);
    }
    if (!(m.sigma_s >= 0) || !std::isfinite(m.sigma_s)) {
      bad_option(prefix + "sigma_s", ">= 0 and finite (mm^-1)", m.sigma_s);
    }
    if (!(m.g > -1 && m.g < 1)) bad_option(prefix + "g", "in (-1, 1)", m.g);
    if (!(m.eta > 0) || !std::isfinite(m.eta)) bad_option(prefix + "eta", "> 0 and finite", m.eta);
  }
}

std::string exitance_csv(const PhotonTransportResult& result) {
  const PhotonTransportOptions& o = result.options;
  std::ostringstream s;
  auto rgb = [&](auto&& field) {
    std::string text;
    for (int c = 0; c < 3; ++c) {
      if (c > 0) text += ',';
      text += field(result.channels[static_cast<std::size_t>(c)], c);
    }
    return text;
  };
  auto rgb_estimate = [&](const std::string& key, Estimate ChannelTransportResult::*member) {
    s << "# " << key << '=' << rgb([&](const ChannelTransportResult& ch, int) {
      return format_number(ch.photons > 0 ? (ch.*member).value
                                          : std::numeric_limits<double>::quiet_NaN());
    }) << '\n';
    s << "# " << key << "_se=" << rgb([&](const ChannelTransportResult& ch, int) {
      return format_number(ch.photons > 0 ? (ch.*member).standard_error
                                          : std::numeric_limits<double>::quiet_NaN());
    }) << '\n';
  };
  auto rgb_medium = [&](double materials::Medium<double>::*member) {
    return rgb([&](const ChannelTransportResult&, int c) {
      return format_number(o.media[static_cast<std::size_t>(c)].*member);
    });
  };

  s << "# format=lucent-simulated-exitance version=1\n";
  s << "# photons=" << rgb([](const ChannelTransportResult& ch, int) {
    return std::to_string(ch.photons);
  }) << '\n';
  s << "# seed=" << result.seed << '\n';
  s << "# sigma_a_per_mm=" << rgb_medium(&materials::Medium<double>::sigma_a) << '\n';
  s << "# sigma_s_per_mm=" << rgb_medium(&materials::Medium<double>::sigma_s) << '\n';
  s << "# g=" << rgb_medium(&materials::Medium<double>::g) << '\n';
  s << "# eta=" << rgb_medium(&materials::Medium<double>::eta) << '\n';
  s << "# thickness_mm=" << format_number(o.thickness_mm)
    << " side=" << (o.far_side ? "transmitted" : "reflected") << '\n';
  s << "# incidence_deg=" << format_number(o.incidence_deg)
    << " azimuth_deg=" << format_number(o.azimuth_deg) << '\n';
  s << "# max_radius_mm=" << format_number(o.max_radius_mm) << '\n';
  s << "# boundary_scoring="
    << (o.boundary_scoring == BoundaryScoring::kSplit ? "split" : "stochastic") << '\n';
  rgb_estimate("diffuse_reflectance", &ChannelTransportResult::diffuse_reflectance);
  rgb_estimate("specular_reflectance", &ChannelTransportResult::specular_reflectance);
  rgb_estimate("transmittance", &ChannelTransportResult::transmittance);
  rgb_estimate("absorbed", &ChannelTransportResult::absorbed);
  // Every comment token is key=value, so a reader can split comment lines on spaces.
  s << "# r_unit=mm r_is=area_weighted_bin_centre R_unit=mm^-2_per_unit_incident_power\n";
  // The annulus of each bin too: a fit averages its model over it (a value at the centre alone
  // is biased where the profile curves across a bin, ~0.5% at sigma_tr x width = 0.35).
  s << "r_mm,R_r,R_g,R_b,se_r,se_g,se_b,r_inner_mm,r_outer_mm\n";
  for (std::size_t b = 0; b < result.bins.size(); ++b) {
    s << format_number(result.bins[b].r_centre_mm);
    for (int pass = 0; pass < 2; ++pass) {
      for (int c = 0; c < 3; ++c) {
        const ChannelTransportResult& ch = result.channels[static_cast<std::size_t>(c)];
        double value = std::numeric_limits<double>::quiet_NaN();
        if (ch.photons > 0 && b < ch.exitance.size()) {
          value = pass == 0 ? ch.exitance[b].value : ch.exitance[b].standard_error;
        }
        s << ',' << format_number(value);
      }
    }
    s << ',' << format_number(result.bins[b].r_inner_mm) << ','
      << format_number(result.bins[b].r_outer_mm) << '\n';
  }
  return s.str();
}

}  // namespace lucent::acquire
