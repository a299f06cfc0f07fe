// The reference's single-scattering term (Scene::single_scattering): collisions on each pixel's
// refracted view ray, each lit through the boundary by the path tracer's connection
// (render/pathtrace/path_walk.h: single_scattering). The environment enters as the scene's
// directional lights that stand for it, as in the reference's multiple-scattering term.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "path_walk.h"
#include "reference_common.h"

namespace lucent::render::detail {

class SingleScatteringTerm {
 public:
  explicit SingleScatteringTerm(const Scene& scene);

  /// One pass: for each object pixel, the mean of `samples` single-scattering estimates per
  /// channel (radiance leaving toward the eye, Fresnel and 1 / eta^2 included).
  std::vector<std::array<double, 3>> pass(const std::vector<PixelHit>& hits,
                                          const std::vector<std::uint32_t>& object_pixels,
                                          int samples, std::uint64_t seed, int pass,
                                          int threads) const;
  std::uint64_t connection_failures() const { return failures_; }

 private:
  static Scene lights_of(const Scene& scene);
  const Scene lights_scene_;
  const pathtrace::Boundary boundary_;
  const pathtrace::Lights lights_;
  const PathTraceOptions options_;
  double eta_ = 1;
  const pathtrace::MediumRgb medium_;
  const pathtrace::World world_;
  mutable std::uint64_t failures_ = 0;
};

}  // namespace lucent::render::detail
