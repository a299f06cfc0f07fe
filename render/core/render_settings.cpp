// Validation and self-description of RenderSettings and RenderStats (render_settings.h).
#include "lucent/render/render_settings.h"

#include <cmath>
#include <sstream>

#include "lucent/core/error.h"

namespace lucent::render {
namespace {

void require(bool ok, const std::string& option, const std::string& what, double value) {
  if (!ok) {
    std::ostringstream s;
    s << option << ": " << what << ", got " << value;
    throw Error(s.str());
  }
}

}  // namespace

void RenderSettings::validate() const {
  // The upper bounds keep a typo from running for days or allocating what no GPU has.
  require(frames >= 1 && frames <= 100000, "--maps-frames", "must be 1..100000", frames);
  require(directions >= 1 && directions <= 256, "--maps-directions", "must be 1..256", directions);
  require(samples >= 1 && samples <= 65536, "--maps-samples", "must be 1..65536", samples);
  require(disc_points >= 1 && disc_points <= 1048576, "--maps-disc-points", "must be 1..1048576",
          disc_points);
  require(samples <= disc_points, "--maps-samples",
          "must not exceed --disc-points (" + std::to_string(disc_points) + ")", samples);
  require(std::isfinite(q) && q > 0 && q <= 1000, "--maps-q", "must be in (0, 1000]", q);
  require(radiance_map_size >= 8 && radiance_map_size <= 8192, "--maps-radiance-map",
          "must be 8..8192 texels", radiance_map_size);
  require(light_map_size >= 8 && light_map_size <= 8192, "--maps-light-map",
          "must be 8..8192 texels", light_map_size);
  require(std::isfinite(exposure) && exposure > 0, "--exposure", "must be positive", exposure);
}

std::string RenderSettings::to_string() const {
  std::ostringstream s;
  s << "RenderSettings{model=" << materials::to_string(model) << ", T=" << frames
    << ", K=" << directions << ", N=" << samples << ", M=" << disc_points << ", disc=" << render::to_string(disc_distribution) << "/"
    << render::to_string(disc_selection) << ", q=" << q
    << ", W_s=" << radiance_map_size << ", W_l=" << light_map_size << ", exposure=" << exposure
    << "}";
  return s.str();
}

DiscSelection parse_disc_selection(const std::string& text) {
  if (text == "nearest") return DiscSelection::kNearest;
  if (text == "strata") return DiscSelection::kStrata;
  throw Error("--maps-disc-selection: expected nearest (Dal Corso 2014) or strata, got '" + text +
              "'");
}

std::string to_string(DiscSelection selection) {
  return selection == DiscSelection::kNearest ? "nearest" : "strata";
}

DiscDistribution parse_disc_distribution(const std::string& text) {
  if (text == "profile") return DiscDistribution::kProfile;
  if (text == "exponential") return DiscDistribution::kExponential;
  throw Error("--maps-disc-distribution: expected profile or exponential (Dal Corso 2014), got '" +
              text + "'");
}

std::string to_string(DiscDistribution distribution) {
  return distribution == DiscDistribution::kProfile ? "profile" : "exponential";
}

nlohmann::json RenderStats::to_json() const {
  nlohmann::json passes = nlohmann::json::array();
  for (const auto& [name, ms] : pass_ms) passes.push_back({{"name", name}, {"ms", ms}});
  return {{"format", "lucent-render-stats"},
          {"version", 1},
          {"technique", technique},
          {"width", width},
          {"height", height},
          {"total_ms", total_ms},
          {"passes", passes},
          {"details", details}};
}

}  // namespace lucent::render
