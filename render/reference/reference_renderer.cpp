// The CPU reference renderer (reference_renderer.h; docs/DESIGN.md §7.5).
#include "lucent/render/reference_renderer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <thread>

#include <Eigen/Geometry>

#include "area_light_irradiance.h"
#include "irradiance_cache.h"
#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/specular.h"
#include "lucent/render/environment.h"
#include "reference_clusters.h"
#include "reference_common.h"
#include "reference_single.h"

namespace lucent::render {
namespace {

using namespace detail;

// render_reference as named stages over one render's state (the former locals of one long function,
// members under the same names): the primary rays, the lights' records and cache, then per pass
// the subsurface light (probes, or area samples with a cluster tree per light group), the pass's
// image folded into the mean, and the statistics.
class ReferenceRun {
 public:
  ReferenceRun(const Scene& scene, DiffusionModel model, const ReferenceOptions& options)
      : scene(scene),
        model(model),
        options(options),
        camera(scene.camera),
        mesh(scene.mesh),
        threads(options.threads > 0 ? options.threads
                                    : std::max(1, int(std::thread::hardware_concurrency()))),
        eta(scene.material.ior),
        media{scene.material.medium(0), scene.material.medium(1), scene.material.medium(2)},
        bssrdf(channel_bssrdfs(scene, model)),
        environment(scene.environment
                        ? std::make_unique<EnvironmentMap>(load_environment(*scene.environment))
                        : nullptr),
        rays(mesh),
        eps(1e-4f * std::max(mesh.bounding_radius(), 1e-6f)),  // ray offset, mm
        W(camera.width),
        H(camera.height),
        pixels(std::size_t(W) * H),
        N(std::size_t(options.surface_samples)),
        sampler(mesh),
        area_sampling(area_light_sampling(options, scene)),
        mean(W, H, 0.0f) {
    for (int c = 0; c < 3; ++c) r_cut[c] = subsurface_cutoff_mm(media[c], model);
  }

  ReferenceImage run() {
    trace_primary_rays();
    if (scene.single_scattering) single_term = std::make_unique<SingleScatteringTerm>(scene);
    prepare_lights();
    work_total = double(options.passes) * double(std::max<std::size_t>(groups, 1)) *
                 double(std::max<std::size_t>(object_pixels.size(), 1));
    for (int pass = 0; pass < options.passes; ++pass) {
      std::vector<std::array<double, 3>> accumulated(object_pixels.size(), {0, 0, 0});
      if (options.sampling == ReferenceSampling::kProbes) {
        probes(pass, accumulated);
      } else {
        area_samples(pass, accumulated);
      }
      std::vector<std::array<double, 3>> single;
      if (single_term) {
        const auto single_start = Clock::now();
        single = single_term->pass(hits, object_pixels, options.single_samples, options.seed,
                                   pass, threads);
        single_ms += ms_since(single_start);
      }
      fold_pass(pass, accumulated, single);
    }
    result.image = mean;
    fill_stats();
    return std::move(result);
  }

 private:
  void trace_primary_rays();
  void prepare_lights();
  void probes(int pass, std::vector<std::array<double, 3>>& accumulated);
  void area_samples(int pass, std::vector<std::array<double, 3>>& accumulated);
  void fold_pass(int pass, const std::vector<std::array<double, 3>>& accumulated,
                 const std::vector<std::array<double, 3>>& single);
  void fill_stats();

  const Clock::time_point start = Clock::now();
  const Scene& scene;
  const DiffusionModel model;
  const ReferenceOptions& options;
  const Camera& camera;
  const Mesh& mesh;
  const int threads;
  const double eta;
  const std::array<materials::Medium<double>, 3> media;
  const std::array<ChannelBssrdf, 3> bssrdf;
  std::array<double, 3> r_cut{};
  const std::unique_ptr<EnvironmentMap> environment;
  const RayScene rays;
  const float eps;
  const int W, H;
  const std::size_t pixels;
  const std::size_t N;  // surface samples per pass (area sampling)
  const SurfaceSampler sampler;
  const AreaLightSampling area_sampling;

  ReferenceImage result;
  std::vector<PixelHit> hits;
  ImageRgb background;
  std::vector<std::uint32_t> object_pixels;
  double primary_ms = 0;
  bool per_light = false;  // one light group per light (directional dipole), else one for all
  std::size_t groups = 0;
  std::unique_ptr<IrradianceCache> cache;
  double area_per_sample = 0;
  ImageRgb mean;
  double sampling_ms = 0, tree_ms = 0, gather_ms = 0;
  std::uint64_t records_total = 0, exact_total = 0, cluster_total = 0;
  double work_total = 0;
  std::mutex progress_mutex;
  std::uint64_t probe_hits = 0;
  std::unique_ptr<SingleScatteringTerm> single_term;
  double single_ms = 0;
  const std::unique_ptr<materials::AngularFactor> angular = angular_factor_for(scene, model);
};

void ReferenceRun::trace_primary_rays() {
  // Primary rays: the camera's pixels, row 0 at the top.
  const Vec3f forward = (camera.target - camera.eye).normalized();
  const Vec3f right = forward.cross(camera.up).normalized();
  const Vec3f up = right.cross(forward);
  const float tan_half = std::tan(camera.fov_y_deg * std::numbers::pi_v<float> / 360.0f);
  const float aspect = float(W) / float(H);
  const auto pixel_direction = [&](std::size_t p) {
    const float sx = (2.0f * (float(p % W) + 0.5f) / W - 1.0f) * tan_half * aspect;
    const float sy = (1.0f - 2.0f * (float(p / W) + 0.5f) / H) * tan_half;
    return Vec3f(forward + sx * right + sy * up).normalized();
  };

  result.mask.assign(pixels, 0);
  hits.resize(pixels);
  background = ImageRgb(W, H, 0.0f);
  const auto primary_start = Clock::now();
  parallel_for(pixels, threads, 256, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      const Vec3f dir = pixel_direction(p);
      unsigned tri = 0;
      float u = 0, v = 0;
      if (!rays.intersect(camera.eye, dir, tri, u, v)) {
        const Vec3f L = environment ? environment_lookup(*environment, dir) : scene.backdrop;
        for (int c = 0; c < 3; ++c) background.data[3 * p + c] = L[c];
        continue;
      }
      const auto& t = mesh.triangles[tri];
      const float b0 = 1 - u - v;
      PixelHit& hit = hits[p];
      hit.x_o = b0 * mesh.positions[t[0]] + u * mesh.positions[t[1]] + v * mesh.positions[t[2]];
      hit.n_o =
          (b0 * mesh.normals[t[0]] + u * mesh.normals[t[1]] + v * mesh.normals[t[2]]).normalized();
      const Vec3f w_o = -dir;
      const double cos_o = hit.n_o.dot(w_o);
      hit.fresnel_out = materials::fresnel_transmittance(cos_o, eta);
      hit.fresnel_reflect = 1.0 - hit.fresnel_out;
      hit.reflected = (2.0f * hit.n_o.dot(w_o) * hit.n_o - w_o).normalized();
      hit.w_o = w_o;
      hit.g_o = (mesh.positions[t[1]] - mesh.positions[t[0]])
                    .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                    .normalized();
      result.mask[p] = 1;
    }
  });
  for (std::size_t p = 0; p < pixels; ++p) {
    if (result.mask[p]) object_pixels.push_back(std::uint32_t(p));
  }
  primary_ms = ms_since(primary_start);
}

void ReferenceRun::prepare_lights() {
  // Light groups: the standard dipole does not depend on the light's direction, so all lights
  // share one record per sample; the directional dipole needs one record set per light.
  per_light = bssrdf[0].depends_on_light();
  groups = per_light ? scene.lights.size() : (scene.lights.empty() ? 0 : 1);
  if (options.irradiance_cache &&
      std::any_of(scene.lights.begin(), scene.lights.end(),
                  [](const Light& l) { return l.type == LightType::kArea; })) {
    IrradianceCacheOptions co;
    co.texel_mm = options.irradiance_cache_texel_mm;
    co.shadow_samples = options.irradiance_cache_samples;
    co.shadows = options.shadows;
    co.coat = area_sampling.coat;
    cache = std::make_unique<IrradianceCache>(mesh, scene.lights, &rays, eta, co);
  }
  area_per_sample = sampler.area() / double(N);
}

// One pass of probe rays (reference_probes.cpp).
void ReferenceRun::probes(int pass, std::vector<std::array<double, 3>>& accumulated) {
  const auto gather_start = Clock::now();
  const double work_before = double(pass) * double(std::max<std::size_t>(object_pixels.size(), 1));
  const double work_all =
      double(options.passes) * double(std::max<std::size_t>(object_pixels.size(), 1));
  probe_pass(scene, model, options, rays, cache.get(), angular.get(), hits, object_pixels, pass,
             threads, accumulated, probe_hits, [&](std::size_t done) {
               if (!options.progress) return;
               std::lock_guard<std::mutex> lock(progress_mutex);
               options.progress(std::min(1.0, (work_before + double(done)) / work_all));
             });
  gather_ms += ms_since(gather_start);
}

// One pass of area samples: their irradiance records, one light group at a time, gathered through
// a cluster tree.
void ReferenceRun::area_samples(int pass, std::vector<std::array<double, 3>>& accumulated) {
  const auto sampling_start = Clock::now();
  // Samples: position, shading normal, geometric normal (for the shadow-ray offset).
  std::vector<Vec3f> xs(N), ns(N), gs(N);
  const std::uint64_t pass_key = mix(options.seed * 0x632BE59BD9B4E019ull + std::uint64_t(pass));
  parallel_for(N, threads, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint64_t key = mix(pass_key ^ (std::uint64_t(k) * 2 + 1));
      sampler.sample(k, N, uniform01(key), uniform01(key ^ 0xA5A5A5A5A5A5A5A5ull), xs[k], ns[k],
                     gs[k]);
    }
  });
  sampling_ms += ms_since(sampling_start);

  // One light group at a time (its records, tree and gather), so that memory stays at one record
  // per sample however many lights an environment map brings.
  for (std::size_t g = 0; g < groups; ++g) {
    // Irradiance records: E = (A/N) radiance cos V F_t.
    const auto records_start = Clock::now();
    const std::size_t first_light = per_light ? g : 0;
    const std::size_t end_light = per_light ? g + 1 : scene.lights.size();
    std::vector<Record> records(N);
    parallel_for(N, threads, 1024, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        Record& r = records[k];
        r.x = xs[k];
        r.n = ns[k];
        r.w = Vec3f::Zero();
        r.E = {0, 0, 0};
        for (std::size_t l = first_light; l < end_light; ++l) {
          const Light& light = scene.lights[l];
          if (light.type == LightType::kArea) {
            // The area light's own estimator (area_light_irradiance.h); the plain mean, since
            // the clusters weight by E and the control variate can make it negative.
            AreaLightSampling sampling = area_sampling;
            sampling.control_variate = false;
            const AreaIrradiance a = area_light_irradiance(
                light, xs[k], ns[k], gs[k], &rays, eps, eta, sampling,
                mix(pass_key ^ (std::uint64_t(k) * 0x2545F4914F6CDD1Dull + l)));
            if (!(a.transmitted > 0)) continue;
            r.w = a.w;
            for (int c = 0; c < 3; ++c) {
              const double kf = angular ? (*angular)(c, double(ns[k].dot(a.w))) : 1.0;
              r.E[c] += float(area_per_sample * a.transmitted * light.radiance[c] * kf);
            }
            continue;
          }
          Vec3f w;
          double irradiance_scale = 1, distance = kInf;
          if (!toward_light(light, xs[k], w, irradiance_scale, distance)) continue;
          const double cos_i = ns[k].dot(w);
          if (!(cos_i > 0)) continue;
          if (options.shadows) {
            // Offset to the light's side of the flat triangle (the shading normal may differ).
            const Vec3f offset = gs[k].dot(w) >= 0 ? gs[k] : Vec3f(-gs[k]);
            if (rays.occluded(xs[k] + eps * offset, w, distance - eps)) continue;
          }
          const double factor = area_per_sample * irradiance_scale * cos_i *
                                materials::fresnel_transmittance(cos_i, eta) *
                                (scene.fur_coat ? scene.fur_coat->at(cos_i) : 1.0);
          r.w = w;
          for (int c = 0; c < 3; ++c)
            r.E[c] += float(factor * light.radiance[c] * (angular ? (*angular)(c, cos_i) : 1.0));
        }
      }
    });
    sampling_ms += ms_since(records_start);

    const auto tree_start = Clock::now();
    std::erase_if(records,
                  [](const Record& r) { return !(r.E[0] > 0 || r.E[1] > 0 || r.E[2] > 0); });
    records_total += records.size();
    const ClusterTree tree(std::move(records));
    tree_ms += ms_since(tree_start);
    const bool point_light = per_light && scene.lights[g].type == LightType::kPoint;

    const auto gather_start = Clock::now();
    std::atomic<std::uint64_t> exact{0}, cluster{0};
    const double work_before =
        (double(pass) * double(std::max<std::size_t>(groups, 1)) + double(g)) *
        double(std::max<std::size_t>(object_pixels.size(), 1));
    parallel_for(
        object_pixels.size(), threads, 16,
        [&](std::size_t begin, std::size_t end) {
          GatherCounters counters;
          for (std::size_t i = begin; i < end; ++i) {
            const PixelHit& hit = hits[object_pixels[i]];
            const auto s = gather(tree, bssrdf, r_cut, options.cluster_ratio, per_light,
                                  point_light, hit.x_o, hit.n_o, hit.w_o, counters);
            for (int c = 0; c < 3; ++c) accumulated[i][c] += s[c];
          }
          exact += counters.exact;
          cluster += counters.cluster;
        },
        [&](std::size_t done) {
          if (!options.progress) return;
          std::lock_guard<std::mutex> lock(progress_mutex);
          options.progress(std::min(1.0, (work_before + double(done)) / work_total));
        });
    exact_total += exact;
    cluster_total += cluster;
    gather_ms += ms_since(gather_start);
  }
}

// The pass's image (subsurface, environment reflection, specular), folded into the running mean.
void ReferenceRun::fold_pass(int pass, const std::vector<std::array<double, 3>>& accumulated,
                             const std::vector<std::array<double, 3>>& single) {
  ImageRgb image = background;
  for (std::size_t i = 0; i < object_pixels.size(); ++i) {
    const std::size_t p = object_pixels[i];
    const PixelHit& hit = hits[p];
    Vec3f reflection = Vec3f::Zero();
    if (options.environment_reflection && environment) {
      // Under a fur coat the mirror direction's light crosses it too (cos_i = cos_o there).
      const double coat = scene.fur_coat ? scene.fur_coat->at(double(hit.n_o.dot(hit.w_o))) : 1.0;
      reflection =
          float(hit.fresnel_reflect * coat) * environment_lookup(*environment, hit.reflected);
    }
    const Vec3f specular = specular_radiance(
        scene, rays, hit, eps, mix(options.seed ^ (std::uint64_t(pass) << 40) ^ std::uint64_t(p)));
    for (int c = 0; c < 3; ++c) {
      const double k = angular ? (*angular)(c, double(hit.n_o.dot(hit.w_o))) : 1.0;
      image.data[3 * p + c] = float(hit.fresnel_out * k * accumulated[i][c] +
                                    (single.empty() ? 0.0 : single[i][std::size_t(c)])) +
                              reflection[c] + specular[c];
    }
  }
  const float blend = 1.0f / float(pass + 1);
  for (std::size_t i = 0; i < mean.data.size(); ++i) {
    mean.data[i] += blend * (image.data[i] * options.exposure - mean.data[i]);
  }
  result.passes.push_back(mean);
}

void ReferenceRun::fill_stats() {
  RenderStats& stats = result.stats;
  stats.technique = "reference";
  stats.width = W;
  stats.height = H;
  stats.pass_ms = {{"primary rays", primary_ms},
                   {"surface samples and shadow rays", sampling_ms},
                   {"cluster trees", tree_ms},
                   {"gather", gather_ms}};
  if (single_term) stats.pass_ms.emplace_back("single scattering", single_ms);
  stats.total_ms = ms_since(start);
  stats.details = {
      {"model", materials::to_string(model)},
      {"sampling", to_string(options.sampling)},
      {"pixel_samples_per_pass", options.pixel_samples},
      {"probe_hits", probe_hits},
      {"surface_samples_per_pass", options.surface_samples},
      {"passes", options.passes},
      {"lights", scene.lights.size()},
      {"object_pixels", object_pixels.size()},
      {"lit_records", records_total},
      {"exact_evaluations", exact_total},
      {"cluster_evaluations", cluster_total},
      {"cluster_ratio", options.cluster_ratio},
      {"shadows", options.shadows},
      {"threads", threads},
      {"seed", options.seed},
      {"single_scattering", single_term != nullptr},
      {"angular", angular != nullptr},
      {"geometry_factor", scene.geometry_factor && materials::geometry_factor_applies(model)},
      {"single_samples_per_pass", single_term ? options.single_samples : 0},
      {"single_connection_failures", single_term ? single_term->connection_failures() : 0},
      {"cutoff_mm",
       {std::isinf(r_cut[0]) ? -1.0 : r_cut[0], std::isinf(r_cut[1]) ? -1.0 : r_cut[1],
        std::isinf(r_cut[2]) ? -1.0 : r_cut[2]}}};
}

}  // namespace

ReferenceImage render_reference(const Scene& scene, DiffusionModel model,
                                const ReferenceOptions& options) {
  const Camera& camera = scene.camera;
  const Mesh& mesh = scene.mesh;
  if (camera.width <= 0 || camera.height <= 0) {
    throw Error("reference renderer: the image must be at least 1x1 pixels, got " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  options.validate();
  if (mesh.triangles.empty() || mesh.normals.size() != mesh.positions.size()) {
    throw Error("reference renderer: mesh '" + mesh.name + "' has no triangles or no normals");
  }
  return ReferenceRun(scene, model, options).run();
}

}  // namespace lucent::render
