// The CPU reference's default sampler (reference_renderer.h, ReferenceSampling::kProbes): for each
// pixel's surface point x_o, points x_i are drawn from the material's own radial profile around
// x_o and found on the mesh by probe rays (after King, Kulla, Conty and Fajardo 2013, "BSSRDF
// importance sampling"): an axis a is chosen (the normal n_o with probability 1/2, each tangent
// with 1/4), a radius r from the profile density p_A (profile_sampling.h) and an angle uniformly,
// giving a point on the disc through x_o perpendicular to a; the ray along a through that point,
// within the sphere of radius r_max about x_o, finds every surface point x_i it crosses. Each x_i
// counts with the density of reaching it through any of the three axes (one-sample multiple
// importance sampling, the balance heuristic):
//
//   pdf(x_i) = sum_a P_a p_A(r_a) |g_i . a|,  r_a = distance from x_o to x_i across a,
//
// g_i the geometric normal (the probe's density on the surface is the disc's divided by the
// cosine). The estimate of L_ss(x_o) = sum over lights of the integral of E F_t S_d dA is then
// the mean over probes of the sum over their hits of E F_t S_d / pdf. On a plane every probe
// along n_o hits exactly at the drawn radius, so the estimate is a stratified quadrature of the
// profile itself: its noise is that of the channels' mismatch, not of the mesh's area.
#include <numbers>

#include "lucent/materials/fresnel.h"
#include "profile_sampling.h"
#include "area_light_irradiance.h"
#include "irradiance_cache.h"
#include "reference_common.h"

namespace lucent::render::detail {

namespace {

// An orthonormal basis (b1, b2) completing the unit vector n (Duff et al. 2017).
void basis(const Vec3d& n, Vec3d& b1, Vec3d& b2) {
  const double s = n.z() >= 0 ? 1.0 : -1.0;
  const double a = -1.0 / (s + n.z());
  const double b = n.x() * n.y() * a;
  b1 = Vec3d(1.0 + s * n.x() * n.x() * a, s * b, -s * n.x());
  b2 = Vec3d(b, s + n.y() * n.y() * a, -n.y());
}

constexpr int kMaxHitsPerProbe = 32;

// What the lights send into the surface at a probe's hit x_f (triangle `tri`, geometric normal
// g_f, shading normal n_f) and out at the pixel's x_o, over the probe density `pdf`: added to
// `sum`. `key` and `n` (the hit's index along the probe) seed the area lights' points.
struct ProbeShading {
  const Scene& scene;
  const ReferenceOptions& options;
  const RayScene& rays;
  const IrradianceCache* cache;
  const std::array<ChannelBssrdf, 3>& bssrdf;
  bool per_light;
  AreaLightSampling area_sampling;
  float eps;
  double eta;
  const materials::AngularFactor* angular;  // null: the radial model's F_t alone
};

// The incidence side's angular factor per channel (1 without one).
std::array<double, 3> incidence_factor(const materials::AngularFactor* angular, double cos_i) {
  if (angular == nullptr) return {1, 1, 1};
  return {(*angular)(0, cos_i), (*angular)(1, cos_i), (*angular)(2, cos_i)};
}

void add_hit(const ProbeShading& ps, unsigned tri, const Vec3f& x_f, const Vec3f& g_f,
             const Vec3f& n_f, const Vec3d& x_o, const Vec3d& n_o, const Vec3d& w_o, double pdf,
             std::uint64_t key, int n, std::array<double, 3>& sum) {
  const Scene& scene = ps.scene;
  const ReferenceOptions& options = ps.options;
  const RayScene& rays = ps.rays;
  const IrradianceCache* cache = ps.cache;
  const std::array<ChannelBssrdf, 3>& bssrdf = ps.bssrdf;
  const bool per_light = ps.per_light;
  const AreaLightSampling& area_sampling = ps.area_sampling;
  const float eps = ps.eps;
  const double eta = ps.eta;
  const Vec3d x_i = x_f.cast<double>(), n_i = n_f.cast<double>();
  std::array<double, 3> radial{0, 0, 0};
  if (!per_light) {
    for (int c = 0; c < 3; ++c) radial[c] = bssrdf[c](x_i, n_i, n_i, x_o, n_o, w_o);
  }
  if (cache) {
    Vec3f w_cache;
    const auto E = cache->lookup(tri, x_f, &w_cache);
    const Vec3d w_i = w_cache.cast<double>();
    const std::array<double, 3> k = incidence_factor(ps.angular, n_i.dot(w_i));
    for (int c = 0; c < 3; ++c) {
      const double s_d = per_light ? bssrdf[c](x_i, n_i, w_i, x_o, n_o, w_o) : radial[c];
      sum[c] += E[std::size_t(c)] / pdf * s_d * k[c];
    }
  }
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    if (light.type == LightType::kArea) {
      if (cache) continue;
      const AreaIrradiance a =
          area_light_irradiance(light, x_f, n_f, g_f, &rays, eps, eta, area_sampling,
                                mix(key ^ (0xA2EAull + std::uint64_t(n) * 0x100000001B3ull + l)));
      if (a.transmitted == 0) continue;
      const Vec3d w_i = a.w.cast<double>();
      const double factor = a.transmitted / pdf;
      const std::array<double, 3> k = incidence_factor(ps.angular, n_i.dot(w_i));
      for (int c = 0; c < 3; ++c) {
        const double s_d = per_light ? bssrdf[c](x_i, n_i, w_i, x_o, n_o, w_o) : radial[c];
        sum[c] += factor * light.radiance[c] * s_d * k[c];
      }
      continue;
    }
    Vec3f w;
    double scale = 1, distance = kInf;
    if (!toward_light(light, x_f, w, scale, distance)) continue;
    const double cos_i = n_f.dot(w);
    if (!(cos_i > 0)) continue;
    if (options.shadows) {
      const Vec3f off = g_f.dot(w) >= 0 ? g_f : Vec3f(-g_f);
      if (rays.occluded(x_f + eps * off, w, distance - eps)) continue;
    }
    const double factor = scale * cos_i * materials::fresnel_transmittance(cos_i, eta) *
                          (scene.fur_coat ? scene.fur_coat->at(cos_i) : 1.0) / pdf;
    const Vec3d w_i = w.cast<double>();
    const std::array<double, 3> k = incidence_factor(ps.angular, cos_i);
    for (int c = 0; c < 3; ++c) {
      const double s_d = per_light ? bssrdf[c](x_i, n_i, w_i, x_o, n_o, w_o) : radial[c];
      sum[c] += factor * light.radiance[c] * s_d * k[c];
    }
  }
}

}  // namespace

void probe_pass(const Scene& scene, DiffusionModel model, const ReferenceOptions& options,
                const RayScene& rays, const IrradianceCache* cache,
                const materials::AngularFactor* angular, const std::vector<PixelHit>& hits,
                const std::vector<std::uint32_t>& object_pixels, int pass, int threads,
                std::vector<std::array<double, 3>>& accumulated, std::uint64_t& probe_hits,
                const std::function<void(std::size_t)>& on_progress) {
  const Mesh& mesh = scene.mesh;
  const double eta = scene.material.ior;
  const double box = (mesh.bounds_max() - mesh.bounds_min()).norm();
  const RadialProfileDensity density(scene.material, model, box);
  if (!density.valid()) return;  // nothing scatters: no subsurface light
  const std::array<ChannelBssrdf, 3> bssrdf = channel_bssrdfs(scene, model);
  const bool per_light = bssrdf[0].depends_on_light();
  const AreaLightSampling area_sampling = area_light_sampling(options, scene);
  const double R = density.r_max();
  const float eps = 1e-4f * std::max(mesh.bounding_radius(), 1e-6f);
  const int S = std::max(1, options.pixel_samples);
  const std::uint64_t pass_key =
      mix(options.seed * 0xD1B54A32D192ED03ull + std::uint64_t(pass) * 0x9E3779B97F4A7C15ull);
  std::atomic<std::uint64_t> total_hits{0};
  const ProbeShading shading{scene,     options,       rays, cache, bssrdf,
                             per_light, area_sampling, eps,  eta,   angular};

  parallel_for(
      object_pixels.size(), threads, 8,
      [&](std::size_t begin, std::size_t end) {
        std::uint64_t local_hits = 0;
        for (std::size_t i = begin; i < end; ++i) {
          const PixelHit& hit = hits[object_pixels[i]];
          const Vec3d x_o = hit.x_o.cast<double>(), n_o = hit.n_o.cast<double>(),
                      w_o = hit.w_o.cast<double>();
          Vec3d t_o, b_o;
          basis(n_o, t_o, b_o);
          const std::array<Vec3d, 3> axes = {n_o, t_o, b_o};
          constexpr std::array<double, 3> P = {0.875, 0.0625, 0.0625};
          const std::uint64_t pixel_key = mix(pass_key ^ (std::uint64_t(object_pixels[i]) << 1));
          const double angle_shift = uniform01(pixel_key ^ 0x5851F42D4C957F2Dull);
          const int axis_shift = int(mix(pixel_key ^ 3) % 16);
          std::array<double, 3> sum{0, 0, 0};
          for (int k = 0; k < S; ++k) {
            const std::uint64_t key = mix(pixel_key + std::uint64_t(k) * 0xA0761D6478BD642Full);
            // Stratified radius quantile, golden-ratio angles, random axis.
            const double u = (k + uniform01(key)) / S;
            const double phi =
                2 * std::numbers::pi *
                std::fmod(k * 0.6180339887498949 + angle_shift + 0.5 * uniform01(key ^ 1), 1.0);
            // The axis by the probe's index (14 of 16 along n_o, one along each tangent), so that
            // every pixel sends exactly its share along each: drawn at random, the count's
            // binomial noise (1 / sqrt(S) per pixel) dominated flat surfaces.
            constexpr std::array<int, 16> kAxisOrder = {0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0};
            const int a = kAxisOrder[std::size_t((k + axis_shift) % 16)];
            const Vec3d& axis = axes[std::size_t(a)];
            const Vec3d& d1 = axes[std::size_t((a + 1) % 3)];
            const Vec3d& d2 = axes[std::size_t((a + 2) % 3)];
            double p_r = 0;
            const double r = density.sample(u, &p_r);
            const double h = std::sqrt(std::max(0.0, R * R - r * r));
            const Vec3d disc = x_o + r * (std::cos(phi) * d1 + std::sin(phi) * d2);
            const Vec3f origin = (disc + h * axis).cast<float>();
            const Vec3f direction = (-axis).cast<float>();
            float t_near = 0;
            for (int n = 0; n < kMaxHitsPerProbe; ++n) {
              unsigned tri = 0;
              float bu = 0, bv = 0, t = 0;
              if (!rays.intersect_segment(origin, direction, t_near, float(2 * h), tri, bu, bv, t))
                break;
              t_near = t + eps;
              const auto& f = mesh.triangles[tri];
              const float b0 = 1 - bu - bv;
              const Vec3f p0 = mesh.positions[f[0]], p1 = mesh.positions[f[1]],
                          p2 = mesh.positions[f[2]];
              const Vec3f x_f = b0 * p0 + bu * p1 + bv * p2;
              const Vec3f g_f = (p1 - p0).cross(p2 - p0).normalized();
              const Vec3f n_f =
                  (b0 * mesh.normals[f[0]] + bu * mesh.normals[f[1]] + bv * mesh.normals[f[2]])
                      .normalized();
              const Vec3d x_i = x_f.cast<double>(), g_i = g_f.cast<double>();
              const Vec3d offset = x_i - x_o;
              double pdf = 0;
              for (int b = 0; b < 3; ++b) {
                const Vec3d& ax = axes[std::size_t(b)];
                // |offset x a|, not sqrt(|offset|^2 - (offset . a)^2): on the far side of an
                // object the difference cancels to rounding and a probe's own hit would get a
                // radius of ~0 (no density) and a weight of 1e10. The probe's own axis takes the
                // density of the radius it drew: recomputed from a far hit's float position, a
                // radius near the density's lower end (1e-4 mean free paths) fell below it by
                // rounding, to a density of 0 and a weight of 1e8-1e9 (the fireflies, 40-70x their
                // neighbours, of a back-lit skin1 sphere at 4096 probes).
                const double r_b = offset.cross(ax).norm();
                const double p_b = b == a ? p_r : density.density_per_mm2(r_b);
                pdf += P[std::size_t(b)] * p_b * std::abs(g_i.dot(ax));
              }
              if (!(pdf > 0)) continue;
              // Russian roulette on hits the profile gives little to (the far side of an object
              // reached by a probe through x_o's neighbourhood): p_A(|x_i - x_o|) / pdf is ~2 for a
              // near hit and ~1e-6 across a sphere; below 0.2 the hit survives with that ratio /
              // 0.2 and counts 1 / survival times (unbiased), saving its shadow rays and BSSRDFs.
              double survival = std::min(1.0, density.density_per_mm2(offset.norm()) / pdf / 0.2);
              if (survival < 1) {
                if (!(uniform01(key ^ (0x9E37u + std::uint64_t(n))) < survival)) continue;
              } else {
                survival = 1;
              }
              pdf *= survival;
              ++local_hits;

              add_hit(shading, tri, x_f, g_f, n_f, x_o, n_o, w_o, pdf, key, n, sum);
            }
          }
          for (int c = 0; c < 3; ++c) accumulated[i][c] += sum[c] / S;
        }
        total_hits += local_hits;
      },
      on_progress);
  probe_hits += total_hits;
}

}  // namespace lucent::render::detail
