// The lack-of-fit statistic on residuals whose truth is known: white noise, noise with a smooth
// model error of stated size, and runs of one sign.
#include "lack_of_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace lucent::fit::detail {
namespace {

std::vector<double> radii(int n) {
  std::vector<double> r;
  for (int i = 0; i < n; ++i) r.push_back(0.05 * std::pow(1000.0, double(i) / (n - 1)));
  return r;
}

TEST(LackOfFit, WhiteNoiseOfAnyScaleStaysBelowTheBar) {
  // 2000 profiles of 30..300 bins, noise 0.3..3 times the stated errors (a fit's Birge ratio takes
  // the scale; structure is judged against the residuals' own scatter): a bar that refuses more
  // than 1 in 100 of these would refuse good fits.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  int above = 0, trials = 0;
  for (int t = 0; t < 2000; ++t, ++trials) {
    const int n = 30 + int(rng() % 271);
    const double scale = std::pow(10.0, -0.5 + double(rng() % 1000) / 1000);
    std::vector<double> e(static_cast<std::size_t>(n));
    for (double& v : e) v = scale * normal(rng);
    const RadialStructure s = radial_structure(radii(n), e.data(), n);
    above += s.z > kMaxStructureZ;
  }
  std::printf("white noise: %d of %d above the bar\n", above, trials);
  EXPECT_LE(above, trials / 200) << above << " of " << trials;
}

TEST(LackOfFit, SmoothModelNoiseWithinItsStatedShareIsNotStructure) {
  // The table's own noise is smooth along the radius: the same draw over 20-bin stretches, 0.6 of
  // each residual's error (data 0.8). Without its share it looks like structure; with it, not.
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal;
  int above_without = 0, above_with = 0;
  const int n = 160;
  const std::vector<double> share(std::size_t(n), 0.6);
  for (int t = 0; t < 400; ++t) {
    std::vector<double> e(static_cast<std::size_t>(n));
    double smooth = 0;
    for (int i = 0; i < n; ++i) {
      if (i % 20 == 0) smooth = 0.6 * normal(rng);
      e[std::size_t(i)] = 0.8 * normal(rng) + smooth;
    }
    above_without += radial_structure(radii(n), e.data(), n).z > kMaxStructureZ;
    above_with += radial_structure(radii(n), e.data(), n, share.data()).z > kMaxStructureZ;
  }
  std::printf("smooth model noise: %d of 400 above the bar without its share, %d with\n",
              above_without, above_with);
  EXPECT_GT(above_without, 100);
  EXPECT_LE(above_with, 4);
}

TEST(LackOfFit, RunsOfOneSignAreFoundAndNamed) {
  const int n = 120;
  const std::vector<double> r = radii(n);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  // The far third: the model above the data by 1.5 standard errors (a thin slab's tail).
  std::vector<double> e(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) e[std::size_t(i)] = normal(rng) + (i > 2 * n / 3 ? 1.5 : 0.0);
  RadialStructure s = radial_structure(r, e.data(), n);
  EXPECT_GT(s.z, kMaxStructureZ);
  std::string why = lack_of_fit_reason(s, 'R');
  EXPECT_NE(why.find("channel R"), std::string::npos) << why;
  EXPECT_NE(why.find("thinner than about"), std::string::npos) << why;
  EXPECT_NE(why.find("--thickness-mm"), std::string::npos) << why;
  // The far third below the model: glare.
  for (int i = 0; i < n; ++i) e[std::size_t(i)] = normal(rng) - (i > 2 * n / 3 ? 1.5 : 0.0);
  s = radial_structure(r, e.data(), n);
  EXPECT_GT(s.z, kMaxStructureZ);
  why = lack_of_fit_reason(s, 'G');
  EXPECT_NE(why.find("glare"), std::string::npos) << why;
  // The first fifth above: a beam wider than a pencil.
  for (int i = 0; i < n; ++i) e[std::size_t(i)] = normal(rng) + (i < n / 5 ? 2.0 : 0.0);
  s = radial_structure(r, e.data(), n);
  EXPECT_GT(s.z, kMaxStructureZ);
  why = lack_of_fit_reason(s, 'B');
  EXPECT_NE(why.find("beam"), std::string::npos) << why;
  // Too few bins to judge.
  EXPECT_EQ(radial_structure(radii(20), e.data(), 20).segments(), 0);
}

}  // namespace
}  // namespace lucent::fit::detail
