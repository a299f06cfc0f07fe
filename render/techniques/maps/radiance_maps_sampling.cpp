// Halton points, the biased disc and the fitted cameras of the radiance-map technique
// (radiance_maps_sampling.h).
#include "radiance_maps_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>

#include "lucent/core/error.h"
#include "lucent/materials/profile_table.h"
#include "profile_sampling.h"

namespace lucent::render::detail {

double radical_inverse(unsigned index, unsigned base) {
  double result = 0, scale = 1.0 / base;
  for (unsigned n = index; n > 0; n /= base, scale /= base) result += (n % base) * scale;
  return result;
}

std::vector<Vec3f> halton_sphere_directions(int count) {
  std::vector<Vec3f> out;
  for (int n = 1; n <= count; ++n) {
    const double s = radical_inverse(unsigned(n), 2), t = radical_inverse(unsigned(n), 3);
    const double z = 2 * t - 1, rho = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = 2 * std::numbers::pi * s;
    out.emplace_back(float(rho * std::cos(phi)), float(rho * std::sin(phi)), float(z));
  }
  return out;
}

double sigma_star(const materials::Material& material, double q) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    const double tr = materials::derive_coefficients(material.medium(c)).sigma_tr;
    if (tr > 0) lowest = std::min(lowest, tr);
  }
  return std::isfinite(lowest) ? lowest / q : 0.0;
}

std::string DiscSamples::to_string() const {
  std::ostringstream s;
  s << "DiscSamples{N=" << samples.size() << ", lights=" << light_count.size()
    << ", sigma*=" << sigma_star_per_mm << "/mm, R=" << disc_radius_mm
    << "mm, rho=" << used_radius_mm << "mm, candidates=" << candidates << "}";
  return s.str();
}

Eigen::Vector3d frame_shift(int t) {
  const double phi = 1.3247179572447460;  // plastic number: x^3 = x + 1
  const Eigen::Vector3d a(1 / phi, 1 / (phi * phi), 1 / (phi * phi * phi));
  Eigen::Vector3d s = double(t - 1) * a;
  for (int k = 0; k < 3; ++k) s[k] -= std::floor(s[k]);
  return s;
}

namespace {

// Z(rho) = integral over the disc of radius rho of e^(-sigma* r) dA
//        = 2 pi / sigma*^2 (1 - e^(-sigma* rho) (1 + sigma* rho)), pi rho^2 for sigma* = 0.
double exponential_disc_integral(double sigma, double rho) {
  if (!(sigma > 0)) return std::numbers::pi * rho * rho;
  const double s = sigma * rho;
  return 2 * std::numbers::pi / (sigma * sigma) * (-std::expm1(-s) - std::exp(-s) * s);
}

double wrap01(double v) { return v - std::floor(v); }

// A step through 0..size-1 that visits every offset (coprime with size) and jumps about 0.618 of
// the stratum each time, so that the first frames spread over each stratum instead of walking up
// from its inner end.
long stratum_step(long size) {
  long step = std::max(1L, std::lround(0.6180339887 * double(size)));
  while (std::gcd(step, size) != 1) ++step;
  return step % std::max(size, 1L);
}

}  // namespace

DiscPoints exponential_disc_points(int M, double sigma_star_per_mm, double disc_radius_mm,
                                  const Eigen::Vector3d& shift) {
  if (M < 1) throw Error("--maps-disc-points: need M >= 1, got " + std::to_string(M));
  DiscPoints out;
  out.distribution = DiscDistribution::kExponential;
  out.sigma_star_per_mm = sigma_star_per_mm;
  double R = disc_radius_mm;
  if (sigma_star_per_mm > 0) R = std::min(R, 30.0 / sigma_star_per_mm);
  out.disc_radius_mm = R;
  std::vector<DiscPoints::Point>& kept = out.points;
  kept.reserve(std::size_t(M));
  const double Z = exponential_disc_integral(sigma_star_per_mm, R);
  for (unsigned n = 1; int(kept.size()) < M; ++n) {
    const double s = wrap01(radical_inverse(n, 2) + shift[0]),
                 t = wrap01(radical_inverse(n, 3) + shift[1]),
                 zeta = wrap01(radical_inverse(n, 5) + shift[2]);
    const double r = R * std::sqrt(t);
    ++out.candidates;
    if (zeta < std::exp(-sigma_star_per_mm * r)) {
      const double phi = 2 * std::numbers::pi * s;
      // The kept points are distributed as e^(-sigma* r) / Z(R) on the disc of radius R.
      kept.push_back({r * std::cos(phi), r * std::sin(phi), r,
                      Z * std::exp(sigma_star_per_mm * r) / M,
                      exponential_disc_integral(sigma_star_per_mm, r) / Z});
    }
  }
  std::stable_sort(kept.begin(), kept.end(),
                   [](const DiscPoints::Point& a, const DiscPoints::Point& b) { return a.r < b.r; });
  return out;
}

DiscPoints profile_disc_points(int M, const materials::Material& material,
                               materials::DiffusionModel model, double disc_radius_mm,
                               const Eigen::Vector3d& shift) {
  if (M < 1) throw Error("--maps-disc-points: need M >= 1, got " + std::to_string(M));
  const RadialProfileDensity density(material, model, disc_radius_mm);
  if (!density.valid()) {
    // Nothing scatters: no subsurface light; a uniform disc keeps the sums well defined (zero).
    return exponential_disc_points(M, 0.0, disc_radius_mm, shift);
  }
  DiscPoints out;
  out.distribution = DiscDistribution::kProfile;
  out.disc_radius_mm = density.r_max();
  out.candidates = M;
  out.points.reserve(std::size_t(M));
  const double s_radius = wrap01(0.5 + shift[0]), s_angle = wrap01(shift[1]);
  for (int j = 0; j < M; ++j) {
    double p_area = 0, cdf = 0;
    const double r = density.sample((j + s_radius) / M, &p_area, &cdf);
    const double phi = 2 * std::numbers::pi * wrap01(j * 0.6180339887498949 + s_angle);
    out.points.push_back({r * std::cos(phi), r * std::sin(phi), r, 1.0 / (M * p_area), cdf});
  }
  return out;  // sorted by radius: the quantile increases with j
}

DiscSamples select_disc_samples(const DiscPoints& disc, int N, int lights, DiscSelection selection,
                                int frame) {
  const int M = int(disc.points.size());
  if (M < 1 || N < 1 || N > M) {
    throw Error("--maps-samples/--maps-disc-points: need 1 <= N <= M, got N=" + std::to_string(N) +
                ", M=" + std::to_string(M));
  }
  if (lights < 1) throw Error("radiance maps: the scene has no lights");
  DiscSamples out;
  out.sigma_star_per_mm = disc.sigma_star_per_mm;
  out.disc_radius_mm = disc.disc_radius_mm;
  out.candidates = disc.candidates;
  const std::vector<DiscPoints::Point>& kept = disc.points;
  const bool strata = selection == DiscSelection::kStrata;
  const bool shrink = N < M && !strata;
  out.used_radius_mm = shrink ? 0.5 * (kept[std::size_t(N) - 1].r + kept[std::size_t(N)].r)
                              : disc.disc_radius_mm;
  // kNearest: the N nearest stand for the part of the sampling density below rho, F(rho) (the
  // points below rho are distributed as the density restricted there).
  double F = 1;
  if (shrink) {
    F = disc.distribution == DiscDistribution::kExponential
            ? exponential_disc_integral(disc.sigma_star_per_mm, out.used_radius_mm) /
                  exponential_disc_integral(disc.sigma_star_per_mm, disc.disc_radius_mm)
            : 0.5 * (kept[std::size_t(N) - 1].cdf + kept[std::size_t(N)].cdf);
  }

  // The N points of this frame and how many of the M each stands for.
  const int L = std::min(lights, N);
  const int t = std::max(frame, 1) - 1;
  std::vector<std::pair<const DiscPoints::Point*, double>> chosen;
  for (int i = 0; i < N; ++i) {
    if (!strata) {
      chosen.emplace_back(&kept[std::size_t(i)], double(M) * F / N);
      continue;
    }
    // Stratum i goes to light (i + t) mod L, so that over L frames every light gathers every
    // stratum; the point within the stratum advances every L frames, by a stride that visits
    // each of its points once in `size` steps, starting from its middle.
    const long begin = long(i) * M / N, end = long(i + 1) * M / N;
    const long size = end - begin;
    const long pick = begin + (size / 2 + long(t / L) * stratum_step(size)) % size;
    chosen.emplace_back(&kept[std::size_t(pick)], double(size));
  }
  // Light l takes every L-th of the radius-sorted points (round-robin: the same spread of radii
  // for every light), in strata mode shifted by the frame. Each of its n_l points stands for
  // N / n_l of the frame's N.
  const int rotation = strata ? t % L : 0;
  for (int l = 0; l < lights; ++l) {
    if (l >= L) {
      // More lights than samples: light l gathers exactly what light l mod L gathers (the same
      // points and weights), so it shares that range: the frame's samples stay N.
      out.light_offset.push_back(out.light_offset[std::size_t(l % L)]);
      out.light_count.push_back(out.light_count[std::size_t(l % L)]);
      continue;
    }
    out.light_offset.push_back(int(out.samples.size()));
    const int first = ((l % L) - rotation + L) % L;
    int count = 0;
    for (int i = first; i < N; i += L) ++count;
    for (int i = first; i < N; i += L) {
      const auto& [p, share] = chosen[std::size_t(i)];
      out.samples.push_back(
          {float(p->x), float(p->y), float(p->weight_mm2 * share * N / count)});
    }
    out.light_count.push_back(int(out.samples.size()) - out.light_offset.back());
  }
  return out;
}

DiscSamples exponential_disc_samples(int M, int N, double sigma_star_per_mm, double disc_radius_mm,
                                     int lights, const Eigen::Vector3d& shift,
                                     DiscSelection selection, int frame) {
  return select_disc_samples(exponential_disc_points(M, sigma_star_per_mm, disc_radius_mm, shift),
                             N, lights, selection, frame);
}

namespace {

Mat4f look_at(const Vec3f& eye, const Vec3f& target, Vec3f up) {
  const Vec3f f = (target - eye).normalized();
  if (std::abs(f.dot(up.normalized())) > 0.999f)
    up = std::abs(f.x()) < 0.9f ? Vec3f::UnitX() : Vec3f::UnitY();
  const Vec3f s = f.cross(up).normalized();
  const Vec3f u = s.cross(f);
  Mat4f m = Mat4f::Identity();
  m.row(0) << s.transpose(), -s.dot(eye);
  m.row(1) << u.transpose(), -u.dot(eye);
  m.row(2) << -f.transpose(), f.dot(eye);
  return m;
}

Mat4f orthographic(float half_extent, float near_mm, float far_mm) {
  Mat4f m = Mat4f::Identity();
  m(0, 0) = 1 / half_extent;
  m(1, 1) = 1 / half_extent;
  m(2, 2) = -2 / (far_mm - near_mm);
  m(2, 3) = -(far_mm + near_mm) / (far_mm - near_mm);
  return m;
}

Mat4f perspective(float fov_y_rad, float aspect, float near_mm, float far_mm) {
  const float f = 1 / std::tan(fov_y_rad / 2);
  Mat4f m = Mat4f::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far_mm + near_mm) / (near_mm - far_mm);
  m(2, 3) = 2 * far_mm * near_mm / (near_mm - far_mm);
  m(3, 2) = -1;
  return m;
}

}  // namespace

LayerCamera fitted_orthographic(const Vec3f& centre, float radius_mm, const Vec3f& toward_camera) {
  LayerCamera c;
  c.direction = toward_camera.normalized();
  const float r = radius_mm * 1.02f;  // a texel of margin around the silhouette
  const Vec3f eye = centre + 2 * r * c.direction;
  c.near_mm = r;
  c.far_mm = 3 * r;
  c.extent_mm = 2 * r;
  c.view_proj = orthographic(r, c.near_mm, c.far_mm) * look_at(eye, centre, Vec3f::UnitY());
  return c;
}

LayerCamera fitted_perspective(const Vec3f& centre, float radius_mm, const Vec3f& eye) {
  LayerCamera c;
  const float r = radius_mm * 1.02f;
  const float distance = (eye - centre).norm();
  c.direction = distance > 0 ? Vec3f((eye - centre) / distance) : Vec3f::UnitZ();
  const float half_angle =
      distance > 1.05f * r ? std::asin(r / distance) : 75.0f * std::numbers::pi_v<float> / 180.0f;
  c.near_mm = std::max(distance - r, 1e-3f * std::max(distance, r));
  c.far_mm = distance + r;
  c.extent_per_mm = 2 * std::tan(half_angle);
  const Vec3f target = distance > 0 ? centre : Vec3f(eye - Vec3f::UnitZ());
  c.view_proj =
      perspective(2 * half_angle, 1.0f, c.near_mm, c.far_mm) * look_at(eye, target, Vec3f::UnitY());
  return c;
}

LayerCamera fitted_area_perspective(const Vec3f& centre, float radius_mm, const Vec3f& eye,
                                    const Vec3f& normal) {
  const float r = radius_mm * 1.02f;
  const float distance = (eye - centre).norm();
  if (distance > 1.05f * r) return fitted_perspective(centre, radius_mm, eye);
  LayerCamera c;
  c.direction = -normal.normalized();
  const float half_angle = 75.0f * std::numbers::pi_v<float> / 180.0f;
  c.near_mm = 1e-3f * std::max(distance, r);
  c.far_mm = distance + r;
  c.extent_per_mm = 2 * std::tan(half_angle);
  const Vec3f forward = normal.normalized();
  const Vec3f up = std::abs(forward.y()) < 0.9f ? Vec3f::UnitY() : Vec3f::UnitZ();
  c.view_proj =
      perspective(2 * half_angle, 1.0f, c.near_mm, c.far_mm) * look_at(eye, eye + forward, up);
  return c;
}

Mat4f camera_view_proj(const Camera& camera, const Vec3f& centre, float radius_mm) {
  const float distance = (camera.eye - centre).norm();
  const float r = radius_mm * 1.05f;
  const float near_mm = std::max(distance - r, 1e-3f * std::max(distance, r));
  const float far_mm = distance + r;
  return perspective(camera.fov_y_deg * std::numbers::pi_v<float> / 180.0f,
                     float(camera.width) / float(camera.height), near_mm, far_mm) *
         look_at(camera.eye, camera.target, camera.up);
}

int blur_level_for_frame(int t, int T, int max_level) {
  if (t >= T || max_level <= 0) return 0;
  const double level = std::ceil(0.5 * std::log2(double(T) / std::max(t, 1)) - 1e-9);
  return std::clamp(int(level), 0, max_level);
}

}  // namespace lucent::render::detail
