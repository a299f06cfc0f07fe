// The fur tile of Klotzli & Olano on the CPU (render/include/lucent/render/fur.h).
#include "lucent/render/fur.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <thread>

#include "lucent/core/error.h"

namespace lucent::render::fur {

namespace {

constexpr double kPi = std::numbers::pi;

// 12-point Gauss-Legendre on [-1, 1] (nodes and weights, symmetric halves).
constexpr double kGaussX[6] = {0.1252334085114689, 0.3678314989981802, 0.5873179542866175,
                               0.7699026741943047, 0.9041172563704749, 0.9815606342467192};
constexpr double kGaussW[6] = {0.2491470458134028, 0.2334925365383548, 0.2031674267230659,
                               0.1600783285433462, 0.1069393259953184, 0.0471753363865118};

template <typename F>
double gauss12(F&& f, double a, double b) {
  const double h = 0.5 * (b - a), m = 0.5 * (a + b);
  double sum = 0;
  for (int i = 0; i < 6; ++i) sum += kGaussW[i] * (f(m - h * kGaussX[i]) + f(m + h * kGaussX[i]));
  return sum * h;
}

int wrap(int i, int n) { return ((i % n) + n) % n; }

}  // namespace

std::string to_string(CoverageRule rule) {
  return rule == CoverageRule::kSeed ? "seed" : "exact";
}

std::string FurOptions::to_string() const {
  std::ostringstream s;
  const auto coat = [&](const Coat& c) {
    s << "{hairs=" << c.hairs << ", width=" << c.width_min << ".." << c.width_max
      << ", length=" << c.length << "}";
  };
  s << "FurOptions{texels=" << texels << ", shells=" << shells
    << ", shell_spacing=" << shell_spacing << ", overcoat=";
  coat(overcoat);
  s << ", undercoat=";
  coat(undercoat);
  s << ", curl_max=" << curl_max << ", optical_density=" << optical_density
    << ", coverage=" << fur::to_string(coverage) << ", quadrature_nodes=" << quadrature_nodes
    << ", seed=" << seed << ", tile_mm=" << tile_mm << ", height_mm=" << height_mm << "}";
  return s.str();
}

void FurOptions::validate() const {
  if (texels < 2 || texels > 4096) throw Error("--fur-texels: expected 2..4096");
  if (shells < 1 || shells > 1024) throw Error("--fur-shells: expected 1..1024");
  if (!(shell_spacing > 0) || !std::isfinite(shell_spacing)) {
    throw Error("fur: the shell spacing must be positive (texels)");
  }
  for (const Coat* c : {&overcoat, &undercoat}) {
    if (c->hairs < 0 || !(c->width_min >= 0) || !(c->width_max >= c->width_min) ||
        !(c->length > 0) || !(c->length <= 1)) {
      throw Error("fur: a coat needs hairs >= 0, 0 <= width_min <= width_max and length in (0, 1]");
    }
  }
  if (!(curl_max >= 0) || !(optical_density >= 0)) {
    throw Error("fur: curl and optical density must not be negative");
  }
  if (coverage == CoverageRule::kSeed && (overcoat.width_max > 1 || undercoat.width_max > 1)) {
    throw Error("fur: the seed's coverage rule takes hairs at most one texel wide");
  }
  if (quadrature_nodes < 3 || quadrature_nodes > 256) throw Error("fur: quadrature nodes 3..256");
  if (!(tile_mm > 0) || !(height_mm > 0) || !(tile_mm <= 1e4) || !(height_mm <= 1e4)) {
    throw Error("--fur-tile-mm, --fur-height-mm: expected lengths in (0, 1e4] mm");
  }
  // Over a mesh the coat is height_mm / tile_mm * texels texels tall, and its march that long.
  if (height_mm / tile_mm * texels > 1024) {
    throw Error("--fur-height-mm, --fur-tile-mm: the coat is " +
                std::to_string(height_mm / tile_mm * texels) +
                " texels tall (height / tile width x --fur-texels); expected at most 1024");
  }
}

std::vector<Hair> generate_hairs(const FurOptions& o) {
  o.validate();
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Hair> hairs;
  for (const Coat* coat : {&o.overcoat, &o.undercoat}) {
    for (int k = 0; k < coat->hairs; ++k) {
      Hair h;
      h.base = Eigen::Vector2d(u(rng) * o.texels, u(rng) * o.texels);
      h.width = coat->width_min + (coat->width_max - coat->width_min) * u(rng);
      h.length = coat->length * o.shells;
      const double angle = 2 * kPi * u(rng);
      h.curl = o.curl_max * u(rng) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      hairs.push_back(h);
    }
  }
  return hairs;
}

double disc_square_overlap(const Eigen::Vector2d& c, double r, double x0, double y0) {
  if (!(r > 0)) return 0;
  const double x1 = x0 + 1, y1 = y0 + 1;
  // x = c.x + r sin(theta), half-chord r cos(theta), dx = r cos(theta) d theta.
  const auto angle_of = [&](double x) { return std::asin(std::clamp((x - c.x()) / r, -1.0, 1.0)); };
  const double a = angle_of(x0), b = angle_of(x1);
  if (!(b > a)) return 0;
  std::vector<double> cuts = {a, b};
  for (double y : {y0, y1}) {
    const double d = std::abs(y - c.y());
    if (d < r) {
      const double t = std::acos(d / r);
      for (double s : {-t, t})
        if (s > a && s < b) cuts.push_back(s);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  const auto integrand = [&](double theta) {
    const double h = r * std::cos(theta);
    const double length = std::min(c.y() + h, y1) - std::max(c.y() - h, y0);
    return std::max(length, 0.0) * r * std::cos(theta);
  };
  double area = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) area += gauss12(integrand, cuts[i], cuts[i + 1]);
  return area;
}

std::array<double, 4> seed_coverage(const Eigen::Vector2d& c, double r) {
  std::array<double, 4> out{0, 0, 0, 0};
  const double circle = kPi * r * r;
  const double i1 = std::floor(c.x() - r) + 1, j1 = std::floor(c.y() - r) + 1;
  // Penetrations past the texel's right and lower (next-y) edges.
  const double dx = c.x() + r - i1, dy = c.y() + r - j1;
  // Eq. 1 (Harris and Stocker): a segment of depth d, m = sqrt(d (2r - d)); it approximates the
  // minor segment, so a segment deeper than r is the disc less its complement.
  const auto minor = [&](double d) {
    const double m = std::sqrt(d * (2 * r - d));
    return m > 0 ? 4.0 / 3.0 * d * m + d * d * d / (4 * m) : 0.0;
  };
  const auto chord = [&](double d) {
    if (!(d > 0)) return 0.0;
    if (d >= 2 * r) return circle;
    return d <= r ? minor(d) : circle - minor(2 * r - d);
  };
  const double right = chord(dx), lower = chord(dy);
  if (right == 0 && lower == 0) {  // case 1
    out[0] = circle;
    return out;
  }
  if (lower == 0) {  // case 2, across the right edge
    out[0] = circle - right;
    out[1] = right;
    return out;
  }
  if (right == 0) {  // case 2, across the lower edge
    out[0] = circle - lower;
    out[2] = lower;
    return out;
  }
  // Case 3: the corner. Eq. 2: a quarter disc of the mean of the wedge's two sides.
  const double s1 = std::max(0.0, c.y() + std::sqrt(std::max(0.0, r * r - (i1 - c.x()) * (i1 - c.x()))) - j1);
  const double s2 = std::max(0.0, c.x() + std::sqrt(std::max(0.0, r * r - (j1 - c.y()) * (j1 - c.y()))) - i1);
  const double wedge = 0.25 * kPi * 0.25 * (s1 + s2) * (s1 + s2);
  out[0] = circle - (right + lower - wedge);
  out[1] = right - wedge;
  out[2] = lower - wedge;
  out[3] = wedge;
  return out;
}

FurTile rasterize_hairs(const std::vector<Hair>& hairs, const FurOptions& o) {
  o.validate();
  FurTile tile;
  tile.texels = o.texels;
  tile.shells = o.shells;
  tile.shell_spacing = o.shell_spacing;
  tile.density.assign(std::size_t(o.shells) * o.texels * o.texels, 0.0f);
  const int n = o.texels;
  for (const Hair& hair : hairs) {
    for (int s = 0; s < o.shells; ++s) {
      const double z = s + 0.5;  // the shell's height, shells
      if (z >= hair.length) break;
      const double t = z / hair.length;
      const double r = 0.5 * hair.width * (1 - t);
      const Eigen::Vector2d centre = hair.base + t * t * hair.curl;
      if (o.coverage == CoverageRule::kSeed) {
        const auto f = seed_coverage(centre, r);
        const int i = int(std::floor(centre.x() - r)), j = int(std::floor(centre.y() - r));
        const int di[4] = {0, 1, 0, 1}, dj[4] = {0, 0, 1, 1};
        for (int k = 0; k < 4; ++k) {
          if (f[std::size_t(k)] != 0) {
            tile.at(s, wrap(j + dj[k], n), wrap(i + di[k], n)) += float(f[std::size_t(k)]);
          }
        }
        continue;
      }
      const int i0 = int(std::floor(centre.x() - r)), i1 = int(std::floor(centre.x() + r));
      const int j0 = int(std::floor(centre.y() - r)), j1 = int(std::floor(centre.y() + r));
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const double a = disc_square_overlap(centre, r, i, j);
          if (a > 0) tile.at(s, wrap(j, n), wrap(i, n)) += float(a);
        }
      }
    }
  }
  for (float& d : tile.density) d = std::clamp(d, 0.0f, 1.0f);
  return tile;
}

double transmittance(const FurTile& tile, int s, int y, int x, const Eigen::Vector3d& d,
                     double optical_density) {
  if (!(d.z() > 0)) return 0;  // into the skin
  const int n = tile.texels;
  const double top = tile.shells * tile.shell_spacing;
  const Eigen::Vector3d p(x + 0.5, y + 0.5, (s + 0.5) * tile.shell_spacing);
  const double length = (top - p.z()) / d.z();
  // One texel per step; at most 1e6 (grazing paths, cos theta < 1e-3 of 1024 texels: coarser).
  const int steps = int(std::clamp(std::ceil(length), 1.0, 1e6));
  const double dt = length / steps;
  const auto density = [&](const Eigen::Vector3d& q) {
    // Trilinear between voxel centres, periodic in x and y, clamped in z.
    const double u = q.x() - 0.5, v = q.y() - 0.5, w = std::clamp(q.z() / tile.shell_spacing - 0.5, 0.0, tile.shells - 1.0);
    const int iu = int(std::floor(u)), iv = int(std::floor(v)), iw = std::min(int(std::floor(w)), tile.shells - 1);
    const double fu = u - iu, fv = v - iv, fw = w - iw;
    const int iw1 = std::min(iw + 1, tile.shells - 1);
    double sum = 0;
    for (int k = 0; k < 8; ++k) {
      const int a = k & 1, b = (k >> 1) & 1, c = (k >> 2) & 1;
      const double weight = (a ? fu : 1 - fu) * (b ? fv : 1 - fv) * (c ? fw : 1 - fw);
      if (weight == 0) continue;
      sum += weight * tile.at(c ? iw1 : iw, wrap(iv + b, n), wrap(iu + a, n));
    }
    return sum;
  };
  double tau = 0;
  for (int k = 0; k < steps; ++k) {
    tau += optical_density * density(p + (k + 0.5) * dt * d) * dt;
    if (tau > 40) return 0;  // T < 4e-18
  }
  return std::exp(-tau);
}

namespace {

// The shells' density repeated 2 x 2, so that a shift of up to n texels reads without wrapping.
std::vector<float> padded_density(const FurTile& tile) {
  const int n = tile.texels, N = 2 * n;
  std::vector<float> padded(std::size_t(tile.shells) * N * N);
  for (int l = 0; l < tile.shells; ++l)
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x)
        padded[(std::size_t(l) * N + y) * N + x] = tile.at(l, y % n, x % n);
  return padded;
}

std::vector<double> march_shell(const FurTile& tile, const std::vector<float>& padded, int s,
                                const Eigen::Vector3d& d, double optical_density) {
  const int n = tile.texels, N = 2 * n;
  std::vector<double> tau(std::size_t(n) * n, 0.0);
  if (!(d.z() > 0)) return tau;  // into the skin: T = 0 below
  const double top = tile.shells * tile.shell_spacing, z0 = (s + 0.5) * tile.shell_spacing;
  const double length = (top - z0) / d.z();
  const int steps = int(std::clamp(std::ceil(length), 1.0, 1e6));  // as `transmittance`
  const double dt = length / steps;
  for (int k = 0; k < steps; ++k) {
    const double t = (k + 0.5) * dt;
    // u = x + t d.x for voxel x: the integer part shifts, the fraction is the shell's.
    const double au = t * d.x(), av = t * d.y();
    const double fu0 = std::floor(au), fv0 = std::floor(av);
    const double fu = au - fu0, fv = av - fv0;
    const int ou = wrap(int(fu0), n), ov = wrap(int(fv0), n);
    const double w = std::clamp((z0 + t * d.z()) / tile.shell_spacing - 0.5, 0.0, tile.shells - 1.0);
    const int iw = std::min(int(std::floor(w)), tile.shells - 1), iw1 = std::min(iw + 1, tile.shells - 1);
    const double fw = w - iw, scale = optical_density * dt;
    const double w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
    const float* lo = &padded[std::size_t(iw) * N * N];
    const float* hi = &padded[std::size_t(iw1) * N * N];
    for (int y = 0; y < n; ++y) {
      const std::size_t r0 = std::size_t(y + ov) * N + ou, r1 = r0 + N;
      double* out = &tau[std::size_t(y) * n];
      for (int x = 0; x < n; ++x) {
        const double a = w00 * lo[r0 + x] + w10 * lo[r0 + x + 1] + w01 * lo[r1 + x] + w11 * lo[r1 + x + 1];
        const double b = w00 * hi[r0 + x] + w10 * hi[r0 + x + 1] + w01 * hi[r1 + x] + w11 * hi[r1 + x + 1];
        out[x] += scale * ((1 - fw) * a + fw * b);
      }
    }
  }
  for (double& v : tau) v = v > 40 ? 0.0 : std::exp(-v);  // T < 4e-18 is 0, as `transmittance`
  return tau;
}

}  // namespace

std::vector<double> shell_transmittance(const FurTile& tile, int s, const Eigen::Vector3d& d,
                                        double optical_density) {
  return march_shell(tile, padded_density(tile), s, d, optical_density);
}

void compute_transfer(FurTile& tile, const FurOptions& o, int threads) {
  const ShQuadrature rule = sh_quadrature(o.quadrature_nodes);
  std::vector<ShVector<double>> Y;
  std::vector<std::size_t> upper;
  for (std::size_t k = 0; k < rule.directions.size(); ++k) {
    Y.push_back(sh_basis<double>(rule.directions[k]));
    if (rule.directions[k].z() > 0) upper.push_back(k);
  }
  const int n = tile.texels;
  tile.transfer.assign(tile.density.size() * kShCoefficients, 0.0f);
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  const std::vector<float> padded = padded_density(tile);
  std::atomic<int> next{0};
  const auto work = [&] {
    std::vector<double> t(std::size_t(n) * n * kShCoefficients);
    for (int s; (s = next.fetch_add(1)) < tile.shells;) {
      std::fill(t.begin(), t.end(), 0.0);
      for (std::size_t k : upper) {
        const std::vector<double> T =
            march_shell(tile, padded, s, rule.directions[k], o.optical_density);
        for (std::size_t p = 0; p < T.size(); ++p) {
          const double wT = rule.weights[k] * T[p];
          if (wT == 0) continue;
          double* out = &t[p * kShCoefficients];
          for (int i = 0; i < kShCoefficients; ++i) out[i] += wT * Y[k][std::size_t(i)];
        }
      }
      float* out = &tile.transfer[std::size_t(s) * n * n * kShCoefficients];
      for (std::size_t i = 0; i < t.size(); ++i) out[i] = float(t[i]);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

FurCoat coat_transmittance(const FurTile& tile, double optical_density, int nodes, int azimuths,
                           int threads) {
  if (nodes < 2 || azimuths < 1) throw Error("fur coat: expected >= 2 elevations and >= 1 azimuth");
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  const int n = tile.texels;
  FurCoat coat;
  coat.transmittance.assign(std::size_t(nodes), 0.0f);
  const std::vector<float> padded = padded_density(tile);
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int k; (k = next.fetch_add(1)) < nodes;) {
      const double mu = double(k + 1) / nodes, s = std::sqrt(std::max(0.0, 1 - mu * mu));
      double sum = 0;
      for (int j = 0; j < azimuths; ++j) {
        const double phi = 2 * kPi * (j + 0.5) / azimuths;
        const Eigen::Vector3d d(s * std::cos(phi), s * std::sin(phi), mu);
        for (const double T : march_shell(tile, padded, 0, d, optical_density)) sum += T;
      }
      coat.transmittance[std::size_t(k)] = float(sum / (double(azimuths) * n * n));
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return coat;
}

FurOptions over_mesh(FurOptions options) {
  options.shell_spacing = options.height_mm / options.tile_mm * options.texels / options.shells;
  return options;
}

FurCoat make_fur_coat(const FurOptions& options, int threads) {
  const FurTile tile = rasterize_hairs(generate_hairs(options), options);
  return coat_transmittance(tile, options.optical_density, 16, 8, threads);
}

FurTile make_fur_tile(const FurOptions& options, int threads) {
  FurTile tile = rasterize_hairs(generate_hairs(options), options);
  compute_transfer(tile, options, threads);
  return tile;
}

double shade(const FurTile& tile, int s, int y, int x, const ShVector<double>& light) {
  const float* t =
      &tile.transfer[((std::size_t(s) * tile.texels + y) * tile.texels + x) * kShCoefficients];
  double sum = 0;
  for (int i = 0; i < kShCoefficients; ++i) sum += light[std::size_t(i)] * t[i];
  return sum;
}

}  // namespace lucent::render::fur
