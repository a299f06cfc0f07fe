// The reference's single-scattering term (reference_single.h).
#include "reference_single.h"

namespace lucent::render::detail {

Scene SingleScatteringTerm::lights_of(const Scene& scene) {
  Scene lights;
  lights.lights = scene.lights;  // the environment's directional lights included
  return lights;
}

SingleScatteringTerm::SingleScatteringTerm(const Scene& scene)
    : lights_scene_(lights_of(scene)),
      boundary_(scene.mesh),
      lights_(pathtrace::gather_lights(lights_scene_)),
      medium_(pathtrace::medium_of(scene.material, eta_)),
      world_{boundary_, lights_, medium_, eta_, std::abs(eta_ - 1) < 1e-12, options_, false} {}

std::vector<std::array<double, 3>> SingleScatteringTerm::pass(
    const std::vector<PixelHit>& hits, const std::vector<std::uint32_t>& object_pixels, int samples,
    std::uint64_t seed, int pass, int threads) const {
  std::vector<std::array<double, 3>> out(object_pixels.size(), {0, 0, 0});
  std::mutex mutex;
  parallel_for(object_pixels.size(), threads, 16, [&](std::size_t begin, std::size_t end) {
    pathtrace::WalkCounts counts;
    for (std::size_t i = begin; i < end; ++i) {
      const PixelHit& hit = hits[object_pixels[i]];
      pathtrace::SurfacePoint p;
      p.x = hit.x_o.cast<double>();
      p.n = hit.n_o.cast<double>();
      p.ng = hit.g_o.cast<double>();
      if (p.ng.dot(p.n) < 0) p.ng = -p.ng;
      const pathtrace::Vec3d w_o = hit.w_o.cast<double>().normalized();
      pathtrace::Rgb sum = pathtrace::Rgb::Zero();
      for (int k = 0; k < samples; ++k) {
        std::uint64_t key = mix(seed ^ 0x51e6u);
        key = mix(key + std::uint64_t(pass));
        key = mix(key + object_pixels[i]);
        pathtrace::Random random(mix(key + std::uint64_t(k)));
        sum += pathtrace::single_scattering(world_, p, w_o, random, counts);
      }
      for (int c = 0; c < 3; ++c) out[i][std::size_t(c)] = sum[c] / samples;
    }
    std::lock_guard<std::mutex> lock(mutex);
    failures_ += counts.connection_failures;
  });
  return out;
}

}  // namespace lucent::render::detail
