// The convolution of the fit's model with a system response, against closed forms: two round
// Gaussians convolve to a Gaussian of the summed variances, whichever way the response is given
// (a Gaussian sigma, or a measured radial profile).
#include "system_response.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

namespace lucent::fit::detail {
namespace {

double gauss2d(double r, double s) {
  return std::exp(-r * r / (2 * s * s)) / (2 * std::numbers::pi * s * s);
}

double convolved_at(const Observations& o, std::size_t i, double s1) {
  const std::size_t m = o.conv_nodes.size();
  double v = 0;
  for (std::size_t j = 0; j < m; ++j) v += o.conv_weights[i * m + j] * gauss2d(o.conv_nodes[j], s1);
  return v;
}

TEST(SystemResponse, BesselI0eMatchesItsSeries) {
  for (double x : {0.0, 0.5, 2.0, 3.7, 3.8, 10.0, 100.0}) {
    double series = 0, term = 1;  // sum (x/2)^2k / (k!)^2
    for (int k = 0; k < 400; ++k) {
      series += term;
      term *= (x / 2) * (x / 2) / ((k + 1.0) * (k + 1.0));
      if (term < 1e-18 * series) break;
    }
    // A&S 9.8.2 bounds the error of sqrt(x) e^-x I0(x) (about 0.4) by 1.9e-7: 5e-7 relative.
    EXPECT_NEAR(bessel_i0e(x), std::exp(-x) * series, 1e-6 * std::exp(-x) * series) << x;
  }
}

TEST(SystemResponse, GaussianResponseOfAGaussianIsTheWiderGaussian) {
  ProfileData d;
  Observations o;
  for (double r = 0.05; r < 6; r *= 1.1) o.r.push_back(r);
  const double s1 = 0.4, beam = 0.5;
  EXPECT_FALSE(attach_system_response(o, d, beam).empty());
  double worst = 0;
  for (std::size_t i = 0; i < o.r.size(); ++i) {
    const double want = gauss2d(o.r[i], std::hypot(s1, beam));
    if (want < 1e-6 * gauss2d(0, std::hypot(s1, beam))) continue;
    worst = std::max(worst, std::abs(convolved_at(o, i, s1) / want - 1));
    if (std::getenv("SRDBG")) std::printf("r %.3f rel %.2e\n", o.r[i], convolved_at(o, i, s1) / want - 1);
  }
  std::printf("Gaussian response: worst relative error %.2e\n", worst);
  EXPECT_LT(worst, 2e-3);
}

TEST(SystemResponse, MeasuredResponseIsUsedWhenWiderThanThePixels) {
  ProfileData d;
  d.radial.pixel_mm = 0.1;
  const double beam = 0.5, s1 = 0.4;
  for (double r = 0.025; r < 5; r += 0.05) {
    d.response_r_mm.push_back(r);
    d.response_value.push_back(gauss2d(r, beam));
  }
  d.response_rms_mm = std::sqrt(2.0) * beam;
  Observations o;
  for (double r = 0.05; r < 6; r *= 1.1) o.r.push_back(r);
  EXPECT_FALSE(attach_system_response(o, d, 0).empty());
  double worst = 0;
  for (std::size_t i = 0; i < o.r.size(); ++i) {
    const double want = gauss2d(o.r[i], std::hypot(s1, beam));
    if (want < 1e-4 * gauss2d(0, std::hypot(s1, beam))) continue;
    worst = std::max(worst, std::abs(convolved_at(o, i, s1) / want - 1));
    if (std::getenv("SRDBG")) std::printf("r %.3f rel %.2e\n", o.r[i], convolved_at(o, i, s1) / want - 1);
  }
  std::printf("measured response: worst relative error %.2e\n", worst);
  // The measured response is linear between rings 0.05 mm apart: measured 0.45% at the centre,
  // 1% where the 0.5 mm Gaussian has fallen to 1e-4 of its peak.
  EXPECT_LT(worst, 1.2e-2);
  // A spot of one pixel sigma (a pencil beam imaged by the pixels): not applied; with 3% of its
  // light spread far out (glare), applied.
  d.response_value.clear();
  for (double r : d.response_r_mm) d.response_value.push_back(gauss2d(r, 0.1));
  EXPECT_FALSE(response_is_wide(d));
  EXPECT_TRUE(attach_system_response(o, d, 0).empty());
  EXPECT_TRUE(o.conv_nodes.empty());
  for (std::size_t i = 0; i < d.response_r_mm.size(); ++i) {
    const double r = d.response_r_mm[i], a = 1.0;
    d.response_value[i] = 0.97 * gauss2d(r, 0.1) +
                          0.03 * a / (2 * std::numbers::pi * std::pow(r * r + a * a, 1.5));
  }
  EXPECT_TRUE(response_is_wide(d));
  EXPECT_FALSE(attach_system_response(o, d, 0).empty());
}

}  // namespace
}  // namespace lucent::fit::detail
