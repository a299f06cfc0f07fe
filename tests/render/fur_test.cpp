// render/include/lucent/render/fur.h (Klotzli & Olano on the CPU): exact hair cross-sections
// against geometry, the seed's chord and wedge approximations measured, eq. 4's transmittance
// against closed forms, the precomputed transfer against direct relighting, mirror symmetry (the
// seed's "brighter from one side" defect) and determinism.
#include "lucent/render/fur.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

namespace lucent::render::fur {
namespace {

constexpr double kPi = std::numbers::pi;
using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;

FurOptions small_tile() {
  FurOptions o;
  o.texels = 16;
  o.shells = 8;
  o.overcoat.hairs = 40;
  o.undercoat.hairs = 150;
  o.curl_max = 1.5;
  o.quadrature_nodes = 8;
  return o;
}

TEST(FurCoverage, AHairsCoverageOverItsTexelsSumsToItsArea) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const V2 c(10 * u(rng), 10 * u(rng));
    const double r = 0.05 + 1.5 * u(rng);
    double sum = 0;
    for (int j = int(std::floor(c.y() - r)); j <= int(std::floor(c.y() + r)); ++j)
      for (int i = int(std::floor(c.x() - r)); i <= int(std::floor(c.x() + r)); ++i)
        sum += disc_square_overlap(c, r, i, j);
    EXPECT_NEAR(sum, kPi * r * r, 1e-12 * std::max(1.0, r * r));
  }
  // Inside one texel: the whole disc; centred on a corner: a quarter in each of four texels.
  EXPECT_NEAR(disc_square_overlap(V2(3.5, 2.5), 0.3, 3, 2), kPi * 0.09, 1e-14);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(disc_square_overlap(V2(4, 3), 0.4, 3 + (k & 1), 2 + (k >> 1)), kPi * 0.16 / 4, 1e-14);
  }
}

TEST(FurCoverage, TheSeedsApproximationsMeasured) {
  // Discs of diameter <= 1 across a corner: the seed's wedge (a quarter disc of the mean of its
  // two sides) against the exact corner area, centred on the corner and off it.
  double worst_chord = 0, wedge_centred = 0, wedge_off_min = 1, wedge_off_max = 0;
  for (double r : {0.2, 0.35, 0.5}) {
    for (double off : {0.0, 0.3, 0.6}) {
      const V2 c(1 - off * r, 1 - 0.5 * off * r);  // the corner at (1, 1)
      const auto seed = seed_coverage(c, r);
      const double exact = disc_square_overlap(c, r, 1, 1);
      const double error = std::abs(seed[3] / exact - 1);
      if (off == 0) wedge_centred = std::max(wedge_centred, error);
      else wedge_off_min = std::min(wedge_off_min, error), wedge_off_max = std::max(wedge_off_max, error);
    }
    // Across an edge only: the chord (Harris and Stocker) against the exact segment.
    for (double d : {0.1, 0.5, 1.0, 1.5}) {
      const V2 c(1 + r - d * r, 0.5);
      const auto seed = seed_coverage(c, r);
      worst_chord = std::max(worst_chord, std::abs(seed[1] / disc_square_overlap(c, r, 1, 0) - 1));
    }
  }
  std::printf("seed coverage: chord within %.2f%%; wedge %.2f%% centred on the corner, %.0f-%.0f%% "
              "off it\n",
              100 * worst_chord, 100 * wedge_centred, 100 * wedge_off_min, 100 * wedge_off_max);
  EXPECT_LT(worst_chord, 0.02);
  EXPECT_LT(wedge_centred, 1e-9);       // a quarter disc, exactly
  EXPECT_GT(wedge_off_max, 0.10);       // and far off once the disc moves
}

TEST(FurTransmittance, NoDensityTransmitsEverything) {
  FurOptions o = small_tile();
  o.overcoat.hairs = o.undercoat.hairs = 0;
  const FurTile tile = rasterize_hairs(generate_hairs(o), o);
  for (double z : {0.05, 0.5, 1.0}) {
    const V3 d = V3(0.6, -0.3, z).normalized();
    EXPECT_DOUBLE_EQ(transmittance(tile, 2, 3, 4, d, o.optical_density), 1.0);
  }
  EXPECT_EQ(transmittance(tile, 2, 3, 4, V3(0, 0, -1), o.optical_density), 0.0);  // the skin
}

TEST(FurTransmittance, HomogeneousSlabIsBeerLambert) {
  FurOptions o = small_tile();
  FurTile tile = rasterize_hairs({}, o);
  const double rho = 0.3;
  for (float& d : tile.density) d = float(rho);
  for (int s : {0, 3, 7}) {
    for (double cos_theta : {1.0, 0.7, 0.25}) {
      const double sin_theta = std::sqrt(1 - cos_theta * cos_theta);
      const V3 d(sin_theta * 0.8, sin_theta * 0.6, cos_theta);
      const double h = (o.shells - (s + 0.5)) * o.shell_spacing;  // to the top, texels
      const double expected = std::exp(-o.optical_density * rho * h / cos_theta);
      EXPECT_NEAR(transmittance(tile, s, 5, 9, d, o.optical_density) / expected, 1.0, 1e-6);
    }
  }
}

// The whole-shell march (what the transfer and the coat use) is the per-voxel march of eq. 4
// rearranged: the same samples and weights, so equal to rounding, for directions of every
// octant from the zenith to grazing (paths crossing the tile many times) and every shell.
TEST(FurTransmittance, ShellMarchEqualsThePerVoxelMarch) {
  const FurOptions o = small_tile();
  const FurTile tile = rasterize_hairs(generate_hairs(o), o);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0, lit = 0;
  for (int trial = 0; trial < 24; ++trial) {
    V3 d(u(rng), u(rng), trial < 4 ? 0.02 * (trial + 1) : std::abs(u(rng)) + 0.01);
    d.normalize();
    for (int s = 0; s < o.shells; ++s) {
      const std::vector<double> T = shell_transmittance(tile, s, d, o.optical_density);
      ASSERT_EQ(T.size(), std::size_t(o.texels) * o.texels);
      for (int y = 0; y < o.texels; ++y)
        for (int x = 0; x < o.texels; ++x) {
          const double one = transmittance(tile, s, y, x, d, o.optical_density);
          worst = std::max(worst, std::abs(T[std::size_t(y) * o.texels + x] - one));
          lit += one;
        }
    }
  }
  std::printf("fur shell march vs per-voxel march: worst |dT| %.2e\n", worst);
  EXPECT_GT(lit, 0);  // something got through: the comparison is not of zeros
  EXPECT_LT(worst, 1e-12);
  const std::vector<double> down = shell_transmittance(tile, 3, V3(0, 0.6, -0.8), 1.0);
  for (double T : down) EXPECT_EQ(T, 0.0);  // into the skin
}

TEST(FurTransfer, PrtEqualsDirectRelightingAndIsMirrorSymmetric) {
  const FurOptions o = small_tile();
  const FurTile tile = make_fur_tile(o, 2);
  // A band-limited light: a clamped-cosine lobe's projection (band <= 4) toward (0.5, 0.2, 0.8).
  const V3 toward = V3(0.5, 0.2, 0.8).normalized();
  const ShVector<double> light = sh_lobe(toward);
  const ShQuadrature same = sh_quadrature(o.quadrature_nodes), fine = sh_quadrature(32);
  double worst_same = 0, worst_fine = 0, peak = 0;
  for (int s : {0, 4, 7}) {
    for (int y : {0, 7}) {
      for (int x : {3, 12}) {
        const double prt = shade(tile, s, y, x, light);
        const auto direct = [&](const ShQuadrature& rule) {
          double sum = 0;
          for (std::size_t k = 0; k < rule.directions.size(); ++k) {
            sum += rule.weights[k] * sh_evaluate(light, rule.directions[k]) *
                   transmittance(tile, s, y, x, rule.directions[k], o.optical_density);
          }
          return sum;
        };
        peak = std::max(peak, std::abs(prt));
        worst_same = std::max(worst_same, std::abs(prt - direct(same)));
        worst_fine = std::max(worst_fine, std::abs(prt - direct(fine)));
      }
    }
  }
  std::printf("fur PRT vs direct relighting: same directions %.2e, 32-node rule %.2e (of the "
              "peak %.3g)\n",
              worst_same / peak, worst_fine / peak, peak);
  EXPECT_LT(worst_same / peak, 1e-5);  // the dot product is the integral (float storage)
  EXPECT_LT(worst_fine / peak, 0.05);  // and the 8-node rule integrates it well

  // Mirror the tile in x and the light with it: the image mirrors (to float rounding).
  FurTile mirrored = tile;
  const int n = tile.texels;
  for (int s = 0; s < tile.shells; ++s)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) mirrored.at(s, y, x) = tile.at(s, y, n - 1 - x);
  compute_transfer(mirrored, o, 2);
  const ShVector<double> light_m = sh_lobe(V3(-toward.x(), toward.y(), toward.z()));
  double worst_mirror = 0;
  for (int s = 0; s < tile.shells; s += 3)
    for (int y = 0; y < n; y += 5)
      for (int x = 0; x < n; ++x)
        worst_mirror = std::max(worst_mirror, std::abs(shade(tile, s, y, x, light) -
                                                       shade(mirrored, s, y, n - 1 - x, light_m)));
  std::printf("fur mirror symmetry: worst %.2e of the peak\n", worst_mirror / peak);
  EXPECT_LT(worst_mirror / peak, 1e-5);
}

TEST(FurTile, FiniteNonBlackAndDeterministic) {
  const FurOptions o = small_tile();
  const FurTile a = make_fur_tile(o, 2), b = make_fur_tile(o, 1);
  ASSERT_EQ(a.transfer.size(), std::size_t(o.texels) * o.texels * o.shells * kShCoefficients);
  EXPECT_EQ(a.density, b.density);
  EXPECT_EQ(a.transfer, b.transfer);  // any number of threads
  double covered = 0, lit = 0;
  for (float d : a.density) covered += d;
  const ShVector<double> light = sh_lobe(V3::UnitZ());
  for (int s = 0; s < o.shells; ++s)
    for (int y = 0; y < o.texels; ++y)
      for (int x = 0; x < o.texels; ++x) {
        const double v = shade(a, s, y, x, light);
        ASSERT_TRUE(std::isfinite(v));
        lit += v;
      }
  EXPECT_GT(covered, 0);
  EXPECT_GT(lit, 0);
  // Deeper shells are darker on average (the hairs above shadow them).
  double bottom = 0, top = 0;
  for (int y = 0; y < o.texels; ++y)
    for (int x = 0; x < o.texels; ++x) {
      bottom += shade(a, 0, y, x, light);
      top += shade(a, o.shells - 1, y, x, light);
    }
  EXPECT_LT(bottom, top);
  FurOptions other = o;
  other.seed = 2;
  EXPECT_NE(make_fur_tile(other, 2).density, a.density);
}

}  // namespace
}  // namespace lucent::render::fur
