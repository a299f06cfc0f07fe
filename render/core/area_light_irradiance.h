// The irradiance an area light delivers into the medium at a surface point, for the CPU techniques
// (the reference's two samplers, the hierarchical technique's leaves, the irradiance cache):
//
//   E_t / L = integral over the polygon of V(x, p) F_t(eta, cos_x) cos_x cos_p / |p - x|^2 dA_p,
//
// (times a fur coat's T(cos_x) beside F_t when there is one: fur_coat.h),
//
// estimated with `samples` stratified points p_j uniform by area (Latin-hypercube strata in the
// two coordinates of area_light_point) and one shadow ray each. With the control variate the
// estimate is
//
//   pi F + (A / S) sum_j (V_j F_t(cos_x,j) - 1) h_j,   h_j = cos_x,j cos_p,j / |p_j - x|^2,
//
// the analytic form factor F (polygon_form_factor.h, clipped to the tangent plane, so that it is
// exactly the integral of h over the polygon) plus the sampled difference: still unbiased, and
// where the light is fully visible the difference is only the Fresnel factor's variation, so the
// noise nearly vanishes. It can be negative in a penumbra (the difference's noise); the sums that
// use it are linear, so that is harmless there. Without it, the plain mean (A / S) sum V F_t h.
#pragma once

#include <cstdint>

#include "area_light.h"
#include "reference_common.h"

namespace lucent::render::detail {

struct AreaLightSampling {
  int samples = 4;              ///< points on the polygon (shadow rays) per evaluation
  bool control_variate = true;  ///< add the analytic pi F (see the file comment)
  bool shadows = true;
  const FurCoat* coat = nullptr;  ///< a fur coat's transmittance per sample (fur_coat.h), or none
};

struct AreaIrradiance {
  double transmitted = 0;     ///< E_t / L, sr (see the file comment)
  double unshadowed = 0;      ///< pi F: the irradiance per unit radiance without shadows or Fresnel
  Vec3f w = Vec3f::Zero();    ///< unit direction of the form factor's vector (toward the light)
};

inline AreaLightSampling area_light_sampling(const ReferenceOptions& options, const Scene& scene) {
  return {options.area_light_samples, options.area_light_control_variate, options.shadows,
          scene.fur_coat ? &*scene.fur_coat : nullptr};
}

/// x: the point (mm), n: its shading normal, g: its geometric normal (the shadow-ray offset side),
/// eps: the ray offset (mm), key: the counter-based random stream of this evaluation.
AreaIrradiance area_light_irradiance(const Light& light, const Vec3f& x, const Vec3f& n,
                                     const Vec3f& g, const RayScene* rays, float eps, double eta,
                                     const AreaLightSampling& sampling, std::uint64_t key);

}  // namespace lucent::render::detail
