// render/include/lucent/render/sh_basis.h: the real SH of bands 0-4 against their closed forms at
// known points, orthonormality under an exact quadrature, projections of a constant and of the
// clamped cosine against their known coefficients, exact reconstruction of band-limited functions,
// and rotation against re-projection.
#include "lucent/render/sh_basis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace lucent::render {
namespace {

constexpr double kPi = std::numbers::pi;
using V = Eigen::Vector3d;

TEST(ShBasis, ClosedFormsAtKnownPoints) {
  // Bands 0-2 in Cartesian form (no Condon-Shortley phase): Y00 = 1 / (2 sqrt pi),
  // Y1-1 = c1 y, Y10 = c1 z, Y11 = c1 x with c1 = sqrt(3 / 4 pi); Y2-2 = c2 xy, Y2-1 = c2 yz,
  // Y20 = sqrt(5 / 16 pi) (3z^2 - 1), Y21 = c2 xz, Y22 = c2 / 2 (x^2 - y^2), c2 = sqrt(15 / 4 pi);
  // Y40 = 3 / (16 sqrt pi) (35 z^4 - 30 z^2 + 3); Y44 = 3 sqrt(35) / (16 sqrt pi) (x^4 - 6x^2y^2 + y^4).
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 50; ++trial) {
    const V w = V(g(rng), g(rng), g(rng)).normalized();
    const double x = w.x(), y = w.y(), z = w.z();
    const auto Y = sh_basis<double>(w);
    const double c1 = std::sqrt(3 / (4 * kPi)), c2 = std::sqrt(15 / (4 * kPi));
    EXPECT_NEAR(Y[0], 0.5 / std::sqrt(kPi), 1e-14);
    EXPECT_NEAR(Y[sh_index(1, -1)], c1 * y, 1e-14);
    EXPECT_NEAR(Y[sh_index(1, 0)], c1 * z, 1e-14);
    EXPECT_NEAR(Y[sh_index(1, 1)], c1 * x, 1e-14);
    EXPECT_NEAR(Y[sh_index(2, -2)], c2 * x * y, 1e-13);
    EXPECT_NEAR(Y[sh_index(2, -1)], c2 * y * z, 1e-13);
    EXPECT_NEAR(Y[sh_index(2, 0)], std::sqrt(5 / (16 * kPi)) * (3 * z * z - 1), 1e-13);
    EXPECT_NEAR(Y[sh_index(2, 1)], c2 * x * z, 1e-13);
    EXPECT_NEAR(Y[sh_index(2, 2)], 0.5 * c2 * (x * x - y * y), 1e-13);
    EXPECT_NEAR(Y[sh_index(4, 0)], 3 / (16 * std::sqrt(kPi)) * (35 * z * z * z * z - 30 * z * z + 3),
                1e-13);
    EXPECT_NEAR(Y[sh_index(4, 4)],
                3 * std::sqrt(35.0) / (16 * std::sqrt(kPi)) *
                    (x * x * x * x - 6 * x * x * y * y + y * y * y * y),
                1e-13);
  }
}

TEST(ShBasis, GramMatrixUnderGaussQuadratureIsTheIdentity) {
  const ShQuadrature rule = sh_quadrature(5);
  double total = 0;
  for (double w : rule.weights) total += w;
  EXPECT_NEAR(total, 4 * kPi, 1e-12);
  double worst = 0;
  for (int i = 0; i < kShCoefficients; ++i) {
    for (int j = 0; j < kShCoefficients; ++j) {
      double sum = 0;
      for (std::size_t k = 0; k < rule.directions.size(); ++k) {
        const auto Y = sh_basis<double>(rule.directions[k]);
        sum += rule.weights[k] * Y[std::size_t(i)] * Y[std::size_t(j)];
      }
      worst = std::max(worst, std::abs(sum - (i == j ? 1.0 : 0.0)));
    }
  }
  EXPECT_LT(worst, 1e-12);
  // One node fewer is no longer exact for the top band's products (the rule is tight).
  const ShQuadrature coarse = sh_quadrature(4);
  double top = 0;
  for (std::size_t k = 0; k < coarse.directions.size(); ++k) {
    const auto Y = sh_basis<double>(coarse.directions[k]);
    top += coarse.weights[k] * Y[sh_index(4, 0)] * Y[sh_index(4, 0)];
  }
  EXPECT_GT(std::abs(top - 1), 1e-3);
}

TEST(ShBasis, ConstantAndClampedCosineProjectToTheirKnownCoefficients) {
  const ShQuadrature rule = sh_quadrature(5);
  const auto c = sh_project([](const V&) { return 1.0; }, rule);
  EXPECT_NEAR(c[0], 2 * std::sqrt(kPi), 1e-12);  // integral of Y00 = 4 pi / (2 sqrt pi)
  for (int i = 1; i < kShCoefficients; ++i) EXPECT_NEAR(c[std::size_t(i)], 0, 1e-12);
  // max(0, cos theta) about +z: zonal, sqrt(pi) / 2, sqrt(pi / 3), sqrt(5 pi) / 8, 0, -sqrt(pi) / 16.
  const auto z = sh_lobe(V::UnitZ());
  const double known[5] = {std::sqrt(kPi) / 2, std::sqrt(kPi / 3), std::sqrt(5 * kPi) / 8, 0,
                           -std::sqrt(kPi) / 16};
  for (int l = 0; l < kShBands; ++l) {
    for (int m = -l; m <= l; ++m) {
      EXPECT_NEAR(z[std::size_t(sh_index(l, m))], m == 0 ? known[l] : 0.0, 1e-12)
          << "l " << l << " m " << m;
    }
  }
}

TEST(ShBasis, BandLimitedFunctionsReconstructExactlyAndRotate) {
  std::mt19937 rng(9);
  std::normal_distribution<double> g;
  ShVector<double> c{};
  for (double& v : c) v = g(rng);
  const auto f = [&](const V& w) { return sh_evaluate(c, w); };
  const ShQuadrature rule = sh_quadrature(5);
  const auto back = sh_project(f, rule);
  for (int i = 0; i < kShCoefficients; ++i) EXPECT_NEAR(back[std::size_t(i)], c[std::size_t(i)], 1e-12);
  // Rotation: the sampling method against projecting the turned function.
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(3 * g(rng), V(g(rng), g(rng), g(rng)).normalized()).toRotationMatrix();
    const auto rotated = sh_rotate(c, R);
    const auto projected =
        sh_project([&](const V& w) { return sh_evaluate(c, R.transpose() * w); }, rule);
    for (int i = 0; i < kShCoefficients; ++i) {
      EXPECT_NEAR(rotated[std::size_t(i)], projected[std::size_t(i)], 1e-10) << i;
    }
  }
  // The clamped cosine about any d is the one about +z turned onto d.
  const V d = V(0.3, -0.5, 0.8).normalized();
  const auto turned = sh_rotate(sh_lobe(V::UnitZ()), Eigen::Quaterniond::FromTwoVectors(V::UnitZ(), d).toRotationMatrix());
  const auto direct = sh_lobe(d);
  for (int i = 0; i < kShCoefficients; ++i) EXPECT_NEAR(turned[std::size_t(i)], direct[std::size_t(i)], 1e-10);
}

}  // namespace
}  // namespace lucent::render
