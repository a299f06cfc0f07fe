// The CPU reference's options checked and written out (reference_renderer.h).
#include <cmath>
#include <sstream>
#include <string>

#include "lucent/core/error.h"
#include "lucent/render/reference_renderer.h"

namespace lucent::render {

void ReferenceOptions::validate() const {
  const auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error(what);
  };
  require(pixel_samples >= 1,
          "--reference-samples-pixel: must be at least 1, got " + std::to_string(pixel_samples));
  require(surface_samples >= 1,
          "--reference-samples: must be at least 1, got " + std::to_string(surface_samples));
  require(passes >= 1, "--reference-passes: must be at least 1, got " + std::to_string(passes));
  require(threads >= 0 && threads <= 1024, "--reference-threads: expected 0 (all) to 1024");
  require(area_light_samples >= 1 && area_light_samples <= 4096,
          "--reference-area-light-samples: expected 1..4096");
  require(irradiance_cache_samples >= 1 && std::isfinite(irradiance_cache_texel_mm) &&
              irradiance_cache_texel_mm >= 0,
          "reference: the irradiance cache needs samples >= 1 and a texel size >= 0 mm");
  require(single_samples >= 1 && single_samples <= 1000000,
          "--reference-single-samples: expected 1..1000000, got " + std::to_string(single_samples));
  require(std::isfinite(exposure) && exposure > 0, "reference: the exposure must be positive");
  require(cluster_ratio >= 0 && cluster_ratio < 1, "reference: cluster_ratio must be in [0, 1)");
}

std::string to_string(ReferenceSampling sampling) {
  return sampling == ReferenceSampling::kProbes ? "probes" : "area";
}

std::string ReferenceOptions::to_string() const {
  std::ostringstream s;
  s << "ReferenceOptions{sampling=" << render::to_string(sampling)
    << ", pixel_samples=" << pixel_samples << ", surface_samples=" << surface_samples
    << ", passes=" << passes << ", threads=" << threads << ", seed=" << seed
    << ", shadows=" << shadows << ", area_light_samples=" << area_light_samples
    << ", area_light_control_variate=" << area_light_control_variate
    << ", irradiance_cache=" << irradiance_cache << ", cluster_ratio=" << cluster_ratio
    << ", environment_reflection=" << environment_reflection
    << ", single_samples=" << single_samples << "}";
  return s.str();
}

}  // namespace lucent::render
