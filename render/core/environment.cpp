// Environment maps: loading, lookup, and importance-sampled directional lights (environment.h).
#include "lucent/render/environment.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

std::string lower_extension(const fs::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return e;
}

float luminance(float r, float g, float b) {
  return 0.2126f * r + 0.7152f * g + 0.0722f * b;
}

// Radical inverse in base b of index i: the Halton sequence's coordinate.
double radical_inverse(std::uint64_t i, unsigned base) {
  double inv = 1.0 / base, f = inv, value = 0;
  while (i > 0) {
    value += f * double(i % base);
    i /= base;
    f *= inv;
  }
  return value;
}

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Index of the piecewise-constant bin that xi falls in, given the running sums cdf[0] = 0 <
// ... <= cdf[n] = total, and the fraction of the way through that bin. Bins of zero weight are
// never chosen (upper_bound skips equal entries).
int sample_cdf(const std::vector<double>& cdf, double xi, double& fraction) {
  const double target = xi * cdf.back();
  const auto it = std::upper_bound(cdf.begin() + 1, cdf.end() - 1, target);
  int j = int(it - cdf.begin()) - 1;
  while (j > 0 && !(cdf[j + 1] > cdf[j])) --j;  // xi * total rounded up onto trailing empty bins
  const double width = cdf[j + 1] - cdf[j];
  fraction = width > 0 ? std::clamp((target - cdf[j]) / width, 0.0, 1.0 - 1e-12) : 0.5;
  return j;
}

}  // namespace

std::string EnvironmentMap::to_string() const {
  std::ostringstream s;
  s << "EnvironmentMap{" << source.string() << ", " << image.width << "x" << image.height
    << " lat-long}";
  return s.str();
}

std::vector<std::string> environment_names() {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(data_cache_dir() / "hdri", error))
    if (lower_extension(entry.path()) == ".exr") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

fs::path resolve_environment(const std::string& name_or_path) {
  const fs::path given(name_or_path);
  if (fs::exists(given) || given.has_extension() || given.has_parent_path()) return given;
  const fs::path file = data_cache_dir() / "hdri" / (name_or_path + ".exr");
  if (fs::is_regular_file(file)) return file;
  const std::vector<std::string> names = environment_names();
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  throw Error("--env: '" + name_or_path + "' is neither a file nor a bundled environment map (" +
              (names.empty() ? "none in " + (data_cache_dir() / "hdri").string() +
                                   ": run scripts/install-deps to fetch them"
                             : list) +
              ")");
}

EnvironmentMap load_environment(const fs::path& path) {
  if (!fs::is_regular_file(path)) {
    throw Error(path.string() + ": no such environment map file");
  }
  EnvironmentMap map;
  map.source = path;
  const std::string ext = lower_extension(path);
  if (ext == ".exr") {
    map.image = imaging::read_exr(path);
  } else if (ext == ".hdr") {
    map.image = imaging::read_radiance_hdr(path);
  } else {
    throw Error(path.string() +
                ": environment maps must be OpenEXR (.exr) or Radiance (.hdr) "
                "lat-long images");
  }
  for (float& v : map.image.data) {
    if (!std::isfinite(v)) {
      throw Error(path.string() + ": environment map has non-finite (NaN or infinite) pixels");
    }
    // As for --light: the renderer sums radiance in float; 1e38 overflows at the first product.
    if (v > 1e12f) {
      throw Error(path.string() +
                  ": environment map has a pixel brighter than 1e12 (scale the "
                  "map down; images are relative)");
    }
    v = std::max(v, 0.0f);  // negative radiance (from filtering or compression) is clamped to 0
  }
  return map;
}

Vec3f latlong_direction(float u, float v) {
  const double phi = 2 * kPi * u, theta = kPi * v;
  return Vec3f(float(-std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
               float(std::sin(theta) * std::cos(phi)));
}

Vec2f latlong_coordinates(const Vec3f& direction) {
  const Vec3f d = direction.normalized();
  double phi = std::atan2(-double(d.x()), double(d.z()));
  if (phi < 0) phi += 2 * kPi;
  const double theta = std::acos(std::clamp(double(d.y()), -1.0, 1.0));
  float u = float(phi / (2 * kPi));
  if (u >= 1.0f) u = 0.0f;
  return Vec2f(u, float(theta / kPi));
}

Vec3f environment_lookup(const EnvironmentMap& map, const Vec3f& direction) {
  const auto& img = map.image;
  if (img.empty()) return Vec3f::Zero();
  const Vec2f uv = latlong_coordinates(direction);
  // Texel centres sit at (i + 0.5) / W; wrap in u, clamp in v.
  const float x = uv.x() * img.width - 0.5f,
              y = std::clamp(uv.y() * img.height - 0.5f, 0.0f, float(img.height - 1));
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - x0, fy = y - y0;
  const auto wrap = [&](int i) { return ((i % img.width) + img.width) % img.width; };
  const int xa = wrap(x0), xb = wrap(x0 + 1), ya = y0, yb = std::min(y0 + 1, img.height - 1);
  Vec3f out;
  for (int c = 0; c < 3; ++c) {
    out[c] = (1 - fy) * ((1 - fx) * img.at(xa, ya, c) + fx * img.at(xb, ya, c)) +
             fy * ((1 - fx) * img.at(xa, yb, c) + fx * img.at(xb, yb, c));
  }
  return out;
}

EnvironmentSampler::EnvironmentSampler(const EnvironmentMap& map) : map_(&map) {
  const auto& img = map.image;
  const int W = img.width, H = img.height;
  if (W < 1 || H < 1) throw Error(map.source.string() + ": empty environment map");
  // Weight of texel (i, j): luminance times its solid angle (2 pi / W)(cos theta_j - cos
  // theta_{j+1}), the exact form of the sin(theta) factor of Dal Corso 2014 §4.4 (equal to
  // (2 pi^2 / (W H)) sin(theta) for small texels).
  band_.resize(H);
  for (int j = 0; j < H; ++j) {
    band_[j] = std::cos(kPi * j / H) - std::cos(kPi * (j + 1) / H);
  }
  row_cdf_.assign(H, std::vector<double>(W + 1, 0.0));
  marginal_.assign(H + 1, 0.0);
  for (int j = 0; j < H; ++j) {
    const double texel_sr = 2 * kPi / W * band_[j];
    for (int i = 0; i < W; ++i) {
      const double f = luminance(img.at(i, j, 0), img.at(i, j, 1), img.at(i, j, 2)) * texel_sr;
      row_cdf_[j][i + 1] = row_cdf_[j][i] + f;
    }
    marginal_[j + 1] = marginal_[j] + row_cdf_[j][W];
  }
  total_ = marginal_[H];
}

void EnvironmentSampler::pick(double xi_row, double xi_col, int& i, int& j, float& u,
                              float& v) const {
  const int W = map_->image.width, H = map_->image.height;
  double t_row = 0, t_col = 0;
  j = sample_cdf(marginal_, xi_row, t_row);
  i = sample_cdf(row_cdf_[j], xi_col, t_col);
  // Uniform in solid angle within the texel: cos(theta) uniform across the row's band.
  const double cos_theta = std::cos(kPi * j / H) - t_row * band_[j];
  const double theta = std::acos(std::clamp(cos_theta, -1.0, 1.0));
  u = float((i + t_col) / W), v = float(theta / kPi);
}

Vec3f EnvironmentSampler::sample(double xi_row, double xi_col, double& pdf_sr) const {
  pdf_sr = 0;
  if (black()) return Vec3f(0, 1, 0);
  int i = 0, j = 0;
  float u = 0, v = 0;
  pick(xi_row, xi_col, i, j, u, v);
  const Vec3f direction = latlong_direction(u, v).normalized();
  pdf_sr = pdf(direction);
  return direction;
}

double EnvironmentSampler::pdf(const Vec3f& direction) const {
  if (black()) return 0;
  const auto& img = map_->image;
  const Vec2f uv = latlong_coordinates(direction);
  const int i = std::clamp(int(uv.x() * img.width), 0, img.width - 1);
  // The row whose band holds cos(theta) (as pick draws it), not the rounded v.
  const double cos_theta = std::cos(kPi * double(uv.y()));
  int j = std::clamp(int(uv.y() * img.height), 0, img.height - 1);
  while (j > 0 && cos_theta > std::cos(kPi * j / img.height)) --j;
  while (j + 1 < img.height && cos_theta < std::cos(kPi * (j + 1) / img.height)) ++j;
  return luminance(img.at(i, j, 0), img.at(i, j, 1), img.at(i, j, 2)) / total_;
}

std::vector<Light> environment_lights(const EnvironmentMap& map, int count, std::uint64_t seed) {
  if (count < 1) throw Error("--env: the number of lights must be at least 1");
  const EnvironmentSampler sampler(map);
  const auto& img = map.image;
  const double total = sampler.total();  // integral of luminance over the sphere
  if (sampler.black()) return {};

  std::uint64_t state = seed;
  const double offset_u = double(splitmix64(state) >> 11) * 0x1.0p-53;
  const double offset_v = double(splitmix64(state) >> 11) * 0x1.0p-53;
  std::vector<Light> lights;
  lights.reserve(count);
  for (int k = 0; k < count; ++k) {
    const double xi_row = std::fmod(radical_inverse(k + 1, 2) + offset_v, 1.0);
    const double xi_col = std::fmod(radical_inverse(k + 1, 3) + offset_u, 1.0);
    int i = 0, j = 0;
    float u = 0, v = 0;
    sampler.pick(xi_row, xi_col, i, j, u, v);

    // pdf per sr = luminance / total, constant over the texel; with the texel's own radiance the
    // estimate L / (count pdf) is exact for a piecewise-constant map.
    const Vec3f texel(img.at(i, j, 0), img.at(i, j, 1), img.at(i, j, 2));
    const double lum = luminance(texel[0], texel[1], texel[2]);
    Light light;
    light.type = LightType::kDirectional;
    light.direction = latlong_direction(u, v).normalized();
    light.radiance = (texel.cast<double>() * (total / (lum * count))).cast<float>();
    lights.push_back(light);
  }
  return lights;
}

}  // namespace lucent::render
