// The convolution of the fit's model with a system response, against closed forms: two round
// Gaussians convolve to a Gaussian of the summed variances, whichever way the response is given
// (a Gaussian sigma, or a measured radial profile).
#include "system_response.h"
#include "convolution_2d.h"

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

// Far from the entry a narrow measured response spans a sliver of each circle: at 20-50 mm a
// 0.5 mm Gaussian given as rings convolves a slowly falling profile as the closed form (the
// Gaussian's Bessel kernel) does, within 0.5% (integrated over the whole half circle, 96
// midpoints hit it 2 to 4 times: a potato's far tail was 10 SD off).
TEST(SystemResponse, MeasuredResponseFarOutMatchesTheClosedForm) {
  ProfileData d;
  d.radial.pixel_mm = 0.1;
  const double beam = 0.5;
  for (double r = 0.025; r < 3.5; r += 0.05) {
    d.response_r_mm.push_back(r);
    d.response_value.push_back(gauss2d(r, beam));
  }
  Observations measured, closed;
  for (double r = 20; r <= 50; r += 5) measured.r.push_back(r), closed.r.push_back(r);
  EXPECT_FALSE(attach_system_response(measured, d, 0).empty());
  EXPECT_FALSE(attach_system_response(closed, d, beam).empty());
  const auto f = [](double s) { return std::exp(-0.05 * s) / s; };
  for (std::size_t i = 0; i < measured.r.size(); ++i) {
    double a = 0, b = 0;
    for (std::size_t j = 0; j < measured.conv_nodes.size(); ++j)
      a += measured.conv_weights[i * measured.conv_nodes.size() + j] * f(measured.conv_nodes[j]);
    for (std::size_t j = 0; j < closed.conv_nodes.size(); ++j)
      b += closed.conv_weights[i * closed.conv_nodes.size() + j] * f(closed.conv_nodes[j]);
    EXPECT_NEAR(a / b, 1.0, 5e-3) << measured.r[i];
  }
}

// A glare veil the white reference's rings lose in their noise (rings within 3 SE of the dark
// field are 0) is carried on past them by the outer rings' power law: at 2-8 mm, beyond the last
// ring kept at 1.5 mm, the response the fit uses is the true veil's (a / (2 pi (r^2 + a^2)^1.5),
// 3%, a = 0.3 mm) within 15%.
TEST(SystemResponse, AGlareTailLostInTheNoiseIsCarriedOn) {
  ProfileData d;
  d.radial.pixel_mm = 0.05;
  const double a = 0.3, share = 0.03;
  const auto veil = [&](double r) {
    return share * a / (2 * std::numbers::pi * std::pow(r * r + a * a, 1.5));
  };
  for (double r = 0.0125; r < 6; r += 0.025) {
    d.response_r_mm.push_back(r);
    d.response_value.push_back(r > 1.5 ? 0.0 : (1 - share) * gauss2d(r, 0.1) + veil(r));
  }
  d.response_rms_mm = 1;
  ASSERT_TRUE(response_is_wide(d));
  Observations o;
  for (double r = 2; r <= 8; r += 1) o.r.push_back(r);
  EXPECT_FALSE(attach_system_response(o, d, 0).empty());
  for (std::size_t i = 0; i < o.r.size(); ++i)
    EXPECT_NEAR(o.conv_point[i] / veil(o.r[i]), 1.0, 0.15) << o.r[i];
  // A Gaussian spot's edge is no power law: nothing is carried past it.
  for (std::size_t i = 0; i < d.response_r_mm.size(); ++i)
    d.response_value[i] = d.response_r_mm[i] > 0.6 ? 0.0 : gauss2d(d.response_r_mm[i], 0.15);
  EXPECT_FALSE(attach_system_response(o, d, 0).empty());
  for (std::size_t i = 0; i < o.r.size(); ++i) EXPECT_EQ(o.conv_point[i], 0.0) << o.r[i];
}

// The 2D grid convolution (oblique captures): pixel means of a round Gaussian of sigma s1 on 0.1 mm
// cells, convolved with a Gaussian response of sigma s2, read at the samples, against the Gaussian
// of the summed variances (pixel means of it); the value and a Jet's derivative part alike.
TEST(SystemResponse, GridConvolutionOfAGaussianIsTheWiderGaussian) {
  const double pixel = 0.1, s1 = 0.4, s2 = 0.5, s12 = std::hypot(s1, s2);
  std::vector<double> x, y;
  for (int j = -30; j <= 30; j += 3)
    for (int i = -40; i <= 40; i += 4) x.push_back(i * pixel + 0.05), y.push_back(j * pixel + 0.05);
  const auto c = make_convolution_2d(
      x, y, pixel, [&](double r) { return gauss2d(r, s2); }, 6 * s2);
  // Cell means by 6 x 6 points, for the model and for the closed form alike.
  const auto cell_mean = [&](double cx, double cy, double s) {
    double m = 0;
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 6; ++b)
        m += gauss2d(std::hypot(cx + ((a + 0.5) / 6 - 0.5) * c->h, cy + ((b + 0.5) / 6 - 0.5) * c->h), s);
    return m / 36;
  };
  std::vector<double> grid(std::size_t(c->nx) * c->ny);
  std::vector<ceres::Jet<double, 1>> jets(grid.size());
  for (int j = 0; j < c->ny; ++j)
    for (int i = 0; i < c->nx; ++i) {
      const double v = cell_mean(c->cell_x(i), c->cell_y(j), s1);
      grid[std::size_t(j) * c->nx + i] = v;
      jets[std::size_t(j) * c->nx + i] = ceres::Jet<double, 1>(v, 0);
      jets[std::size_t(j) * c->nx + i].v[0] = 2 * v;  // a derivative part: convolved alike
    }
  convolve(*c, grid);
  convolve(*c, jets);
  double worst = 0;
  const double peak = gauss2d(0, s12);
  for (std::size_t k = 0; k < x.size(); ++k) {
    double v = 0;
    for (int t = 0; t < 4; ++t) v += c->weights[k][std::size_t(t)] * grid[std::size_t(c->cells[k][std::size_t(t)])];
    const double want = cell_mean(x[k], y[k], s12);
    if (want < 1e-3 * peak) continue;
    worst = std::max(worst, std::abs(v / want - 1));
  }
  std::printf("2D grid convolution: worst relative error %.2e\n", worst);
  // The response at the cells' centres (the model cells hold pixel means): measured 1.6e-8, the
  // kernel's truncation at 6 sigma and the bilinear reads at the samples (which are cell centres).
  EXPECT_LT(worst, 1e-3);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    EXPECT_NEAR(jets[i].a, grid[i], 1e-12 + 1e-9 * std::abs(grid[i]));
    EXPECT_NEAR(jets[i].v[0], 2 * grid[i], 1e-12 + 1e-9 * std::abs(grid[i]));
  }
}

}  // namespace
}  // namespace lucent::fit::detail
