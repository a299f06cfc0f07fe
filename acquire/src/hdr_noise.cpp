// The HDR merge's noise model (hdr_merge_impl.h): quantisation, the non-negative variance fits,
// and the fallback from neighbours.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "hdr_merge_impl.h"

namespace lucent::acquire::detail {
namespace {

// Median of a chi-square variable with one degree of freedom: median(e^2) = 0.45494 sigma^2.
constexpr double kChiSquare1Median = 0.454936423119572;

}  // namespace

// Quantisation variance of each code in linear units: the curve's local step squared over 12.
std::array<std::vector<double>, 3> quantisation_variance(const ResponseCurve& curve) {
  std::array<std::vector<double>, 3> q2;
  const int m = curve.max_value;
  for (int c = 0; c < 3; ++c) {
    const std::vector<double>& f = curve.linear[c];
    q2[c].resize(std::size_t(m) + 1);
    for (int v = 0; v <= m; ++v) {
      const int lo = std::max(v - 1, 0), hi = std::min(v + 1, m);
      const double step = (f[hi] - f[lo]) / (hi - lo);
      q2[c][v] = step * step / 12.0;
    }
  }
  return q2;
}

// Non-negative least squares for y ~ p A + q B with weights w (2 parameters, closed form on each
// face of the constraint set). Returns {p, q}.
std::array<double, 2> fit_non_negative(const std::vector<NoiseRow>& rows) {
  double saa = 0, sab = 0, sbb = 0, say = 0, sby = 0;
  for (const NoiseRow& r : rows) {
    saa += r.w * r.a * r.a;
    sab += r.w * r.a * r.b;
    sbb += r.w * r.b * r.b;
    say += r.w * r.a * r.y;
    sby += r.w * r.b * r.y;
  }
  const auto cost = [&](double p, double q) {
    return p * p * saa + q * q * sbb + 2 * p * q * sab - 2 * p * say - 2 * q * sby;
  };
  std::array<double, 2> best{0.0, 0.0};
  double best_cost = 0.0;  // cost(0, 0)
  const double det = saa * sbb - sab * sab;
  if (det > 1e-12 * saa * sbb && saa > 0 && sbb > 0) {
    const double p = (say * sbb - sby * sab) / det, q = (sby * saa - say * sab) / det;
    if (p >= 0 && q >= 0 && cost(p, q) < best_cost) best = {p, q}, best_cost = cost(p, q);
  }
  if (saa > 0 && say > 0 && cost(say / saa, 0) < best_cost) {
    best = {say / saa, 0.0}, best_cost = cost(say / saa, 0);
  }
  if (sbb > 0 && sby > 0 && cost(0, sby / sbb) < best_cost) best = {0.0, sby / sbb};
  return best;
}

// Reweighted fit: Var(d^2) = 2 E[d^2]^2 for a Gaussian difference, so each row is weighted by the
// inverse square of its predicted E[d^2] (= p a + q b + floor), starting from unit weights.
std::array<double, 2> fit_variance_model(std::vector<NoiseRow>& rows,
                                         const std::vector<double>& floor) {
  std::array<double, 2> pq = fit_non_negative(rows);
  for (int iteration = 0; iteration < 6; ++iteration) {
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const double predicted = pq[0] * rows[i].a + pq[1] * rows[i].b + floor[i];
      rows[i].w = predicted > 0 ? 1.0 / (predicted * predicted) : 0.0;
    }
    pq = fit_non_negative(rows);
  }
  return pq;
}

// The fallback noise model var(L) = a L + b from each pixel's spread around the mean of its four
// neighbours (Var(L0 - mean4) = 1.25 sigma^2 for independent noise of similar size), per channel:
// medians of the squared spread in 32 brightness groups (robust against edges), then a weighted
// non-negative fit. Fills result.noise.
void fit_neighbour_noise(HdrResult& result) {
  const imaging::ImageRgb& image = result.radiance;
  const int w = image.width, h = image.height;
  result.noise = {};
  result.noise.source = "neighbours";
  for (int c = 0; c < 3; ++c) {
    std::vector<std::pair<double, double>> samples;  // (L, spread^2 / 1.25)
    for (int y = 1; y + 1 < h; ++y) {
      for (int x = 1; x + 1 < w; ++x) {
        if (!result.valid(x, y, c) || !result.valid(x - 1, y, c) || !result.valid(x + 1, y, c) ||
            !result.valid(x, y - 1, c) || !result.valid(x, y + 1, c)) {
          continue;
        }
        const double mean4 = 0.25 * (double(image.at(x - 1, y, c)) + image.at(x + 1, y, c) +
                                     image.at(x, y - 1, c) + image.at(x, y + 1, c));
        const double spread = image.at(x, y, c) - mean4;
        samples.emplace_back(image.at(x, y, c), spread * spread / 1.25);
      }
    }
    result.noise.samples += std::int64_t(samples.size());
    if (samples.size() < 64) continue;  // too few to say anything: the model stays 0
    std::sort(samples.begin(), samples.end());
    const std::size_t groups = std::min<std::size_t>(32, samples.size() / 32);
    std::vector<NoiseRow> rows;
    std::vector<double> floor;
    for (std::size_t g = 0; g < groups; ++g) {
      const std::size_t begin = samples.size() * g / groups,
                        end = samples.size() * (g + 1) / groups;
      std::vector<double> spreads;
      double mean_l = 0;
      for (std::size_t i = begin; i < end; ++i) {
        spreads.push_back(samples[i].second);
        mean_l += samples[i].first;
      }
      mean_l /= double(end - begin);
      std::nth_element(spreads.begin(), spreads.begin() + spreads.size() / 2, spreads.end());
      const double variance = spreads[spreads.size() / 2] / kChiSquare1Median;
      rows.push_back({std::max(mean_l, 0.0), 1.0, variance, 1.0});
      floor.push_back(0.0);
    }
    const auto [a, b] = fit_variance_model(rows, floor);
    result.noise.gain[c] = a;
    result.noise.read_variance[c] = b;
  }
}

}  // namespace lucent::acquire::detail
