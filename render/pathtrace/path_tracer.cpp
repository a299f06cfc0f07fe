// `--technique pathtrace` (path_tracer.h): the camera's pixels, pass after pass, each pixel's
// paths per channel (path_walk.cpp), the running mean and each pixel's standard error from the
// spread of its own samples.
#include "lucent/render/path_tracer.h"

#include <sstream>

#include "lucent/core/error.h"
#include "path_walk.h"

namespace lucent::render {
namespace {

using pathtrace::Vec3d;

// The key of sample k of pixel p in pass `pass`: the same whatever thread draws it.
std::uint64_t sample_key(std::uint64_t seed, int pass, std::size_t pixel, int k) {
  std::uint64_t key = detail::mix(seed ^ 0x5bd1e995u);
  key = detail::mix(key + std::uint64_t(pass));
  key = detail::mix(key + pixel);
  return detail::mix(key + std::uint64_t(k));
}

struct CameraRays {
  explicit CameraRays(const Camera& camera)
      : eye(camera.eye.cast<double>()),
        forward((camera.target - camera.eye).cast<double>().normalized()),
        right(forward.cross(camera.up.cast<double>()).normalized()),
        up(right.cross(forward)),
        tan_half(std::tan(double(camera.fov_y_deg) * pathtrace::kPi / 360.0)),
        aspect(double(camera.width) / camera.height),
        W(camera.width),
        H(camera.height) {}
  /// Through (column + fx, row + fy) of the image, row 0 at the top; (0.5, 0.5) is the centre.
  Vec3d direction(std::size_t p, double fx, double fy) const {
    const double sx = (2.0 * (double(p % std::size_t(W)) + fx) / W - 1.0) * tan_half * aspect;
    const double sy = (1.0 - 2.0 * (double(p / std::size_t(W)) + fy) / H) * tan_half;
    return (forward + sx * right + sy * up).normalized();
  }
  Vec3d eye, forward, right, up;
  double tan_half, aspect;
  int W, H;
};

// The statistics of a finished render (--stats): counts, the object's mean and noise.
void fill_stats(PathTraceImage& result, const pathtrace::WalkCounts& counts, double n,
                std::size_t object, double eta, bool matched, std::size_t paths_per_sample,
                double total_ms, double noise_sum, double value_sum) {
  RenderStats& stats = result.stats;
  stats.technique = "pathtrace";
  stats.width = result.image.width;
  stats.height = result.image.height;
  stats.total_ms = total_ms;
  stats.pass_ms = {{"paths", stats.total_ms}};
  const double paths = double(std::max<std::uint64_t>(1, counts.paths));
  stats.details = {{"samples_per_pixel", n},
                   {"paths", counts.paths},
                   {"collisions_per_path", double(counts.collisions) / paths},
                   {"connections", counts.connections},
                   {"connection_failures", counts.connection_failures},
                   {"truncated_paths", counts.truncated},
                   {"leaked_paths", counts.leaks},
                   {"object_pixels", object},
                   {"object_mean", result.object_mean},
                   {"object_mean_standard_error", result.object_mean_error},
                   // The RMS of the pixels' standard errors over the object, relative to its mean.
                   {"relative_pixel_noise", object && value_sum > 0
                                                ? std::sqrt(noise_sum / (3.0 * double(object))) /
                                                      (value_sum / (3.0 * double(object)))
                                                : 0.0},
                   {"eta", eta},
                   {"paths_per_sample", paths_per_sample},
                   {"connection", matched ? "straight (eta = 1)" : "through one refraction"}};
}

}  // namespace

void PathTraceOptions::validate() const {
  if (pixel_samples < 1) throw Error("--pathtrace-samples-pixel: must be at least 1");
  if (passes < 1) throw Error("--pathtrace-passes: must be at least 1");
  if (threads < 0) throw Error("--pathtrace-threads: must be 0 (all cores) or more");
  if (max_collisions < 1) throw Error("pathtrace: max_collisions must be at least 1");
  if (!(exposure > 0) || !std::isfinite(exposure)) throw Error("--exposure: must be positive");
}

std::string PathTraceOptions::to_string() const {
  std::ostringstream s;
  s << "PathTraceOptions{samples_pixel=" << pixel_samples << ", passes=" << passes
    << ", seed=" << seed << ", jitter=" << (jitter ? "on" : "off") << "}";
  return s.str();
}

PathTraceImage render_pathtrace(const Scene& scene, const PathTraceOptions& options) {
  options.validate();
  const auto start = detail::Clock::now();
  const Camera& camera = scene.camera;
  if (camera.width <= 0 || camera.height <= 0) {
    throw Error("--size: the image needs at least one pixel, got " + std::to_string(camera.width) +
                "x" + std::to_string(camera.height));
  }
  if (scene.mesh.triangles.empty()) throw Error("--mesh: the mesh has no triangles");

  const pathtrace::Boundary boundary(scene.mesh);
  const pathtrace::Lights lights = pathtrace::gather_lights(scene);
  double eta = 1;
  const pathtrace::MediumRgb medium = pathtrace::medium_of(scene.material, eta);
  const pathtrace::World world{boundary, lights,        medium, eta, std::abs(eta - 1) < 1e-12,
                               options,  scene.specular};
  const PathTraceOptions& o = options;
  const std::vector<pathtrace::Rgb> groups = pathtrace::channel_groups(medium);
  const CameraRays rays(camera);
  const std::size_t pixels = std::size_t(camera.width) * std::size_t(camera.height);
  const int threads =
      o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));

  PathTraceImage result;
  result.mask.assign(pixels, 0);
  for (std::size_t p = 0; p < pixels; ++p) {
    result.mask[p] = boundary.hit(rays.eye, rays.direction(p, 0.5, 0.5)).has_value() ? 1 : 0;
  }

  // Per pixel and channel: the sum and the sum of squares of its samples' radiance.
  std::vector<std::array<double, 6>> moments(pixels, std::array<double, 6>{});
  std::mutex counts_mutex;
  pathtrace::WalkCounts counts;
  const double units = double(pixels) * o.passes;
  for (int pass = 0; pass < o.passes; ++pass) {
    detail::parallel_for(
        pixels, threads, 8,
        [&](std::size_t begin, std::size_t end) {
          pathtrace::WalkCounts mine;
          for (std::size_t p = begin; p < end; ++p) {
            for (int k = 0; k < o.pixel_samples; ++k) {
              pathtrace::Rgb v = pathtrace::Rgb::Zero();
              for (std::size_t g = 0; g < groups.size(); ++g) {
                pathtrace::Random random(sample_key(o.seed, pass, p, k) + g);
                const double fx = o.jitter ? random.uniform() : 0.5;
                const double fy = o.jitter ? random.uniform() : 0.5;
                v += pathtrace::trace_path(world, rays.eye, rays.direction(p, fx, fy), groups[g],
                                           random, mine);
              }
              for (std::size_t c = 0; c < 3; ++c) {
                moments[p][c] += v[int(c)];
                moments[p][3 + c] += v[int(c)] * v[int(c)];
              }
            }
          }
          std::lock_guard<std::mutex> lock(counts_mutex);
          counts.add(mine);
        },
        [&](std::size_t done) {
          if (o.progress) o.progress((double(pass) * double(pixels) + double(done)) / units);
        });
    if (o.passes > 1) {
      ImageRgb running(camera.width, camera.height, 0.0f);
      const double n = double(pass + 1) * o.pixel_samples;
      for (std::size_t p = 0; p < pixels; ++p)
        for (std::size_t c = 0; c < 3; ++c)
          running.data[3 * p + c] = float(moments[p][c] / n * o.exposure);
      result.passes.push_back(std::move(running));
    }
  }

  // The mean, its standard error, and the object's mean over the mask.
  const double n = double(o.passes) * o.pixel_samples;
  result.image = ImageRgb(camera.width, camera.height, 0.0f);
  result.standard_error = ImageRgb(camera.width, camera.height, 0.0f);
  std::array<double, 3> sum{}, variance{};
  std::size_t object = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      const double mean = moments[p][c] / n;
      const double var = n > 1 ? std::max(0.0, (moments[p][3 + c] - n * mean * mean) / (n - 1)) : 0;
      result.image.data[3 * p + c] = float(mean * o.exposure);
      result.standard_error.data[3 * p + c] = float(std::sqrt(var / n) * o.exposure);
      if (result.mask[p]) sum[c] += mean, variance[c] += var / n;
    }
    object += result.mask[p];
  }
  double noise_sum = 0, value_sum = 0;
  for (std::size_t c = 0; c < 3; ++c) {
    result.object_mean[c] = object ? sum[c] / double(object) : 0;
    result.object_mean_error[c] = object ? std::sqrt(variance[c]) / double(object) : 0;
    noise_sum += variance[c];
    value_sum += sum[c];
  }

  fill_stats(result, counts, n, object, eta, world.matched, groups.size(), detail::ms_since(start),
             noise_sum, value_sum);
  return result;
}

}  // namespace lucent::render
