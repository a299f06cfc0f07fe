// Tests of the Monte Carlo codes' sampling primitives (acquire/src/monte_carlo_random.h): the
// azimuth table against the trigonometric functions, and the directions it turns against their
// distributions' moments.
#include "monte_carlo_random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace lucent::acquire::detail {
namespace {

// The table's angle for a 64-bit draw is bits * 2 pi / 2^64: it must give that angle's cosine and
// sine to rounding, in every sector and at both ends of one.
TEST(AzimuthTable, GivesTheCosineAndSineOfTheDrawnAngle) {
  const AzimuthTable& table = azimuth_table();
  Xoshiro256StarStar rng(3);
  double worst = 0;
  for (int n = 0; n < 200000; ++n) {
    std::uint64_t bits = rng.next();
    if (n % 3 == 1) bits |= (std::uint64_t{1} << 54) - 1;     // the far end of a sector
    if (n % 3 == 2) bits &= ~((std::uint64_t{1} << 54) - 1);  // its start
    double c, s;
    table.sample(bits, c, s);
    // The angle in long double: 2^64 draws over the circle.
    const long double angle =
        static_cast<long double>(bits) * (2 * std::numbers::pi_v<long double> / 0x1.0p64L);
    worst = std::max({worst, std::abs(c - static_cast<double>(std::cos(angle))),
                      std::abs(s - static_cast<double>(std::sin(angle)))});
  }
  // 1e-15: ~4 units in the last place of 1 (the table's rounded entries and the turn's four
  // roundings; 6.7e-16 seen); a series two terms short is 6e-11 off, a wrong sector 6e-3.
  EXPECT_LT(worst, 1e-15);
}

// The azimuth is uniform: the moments of cos and sin over the circle (0 for cos, sin, cos sin,
// cos 2phi; 1/2 for cos^2) and of a sector's index.
TEST(AzimuthTable, IsUniform) {
  Xoshiro256StarStar rng(11);
  constexpr int kN = 1000000;
  double c1 = 0, s1 = 0, cs = 0, c2 = 0, c3 = 0;
  for (int n = 0; n < kN; ++n) {
    double c, s;
    sample_azimuth(rng, c, s);
    c1 += c, s1 += s, cs += c * s, c2 += c * c, c3 += c * c * c - 3 * c * s * s;  // cos 3 phi
  }
  const double se = 1 / std::sqrt(2.0 * kN);  // the SD of cos over the circle is 1/sqrt(2)
  EXPECT_NEAR(c1 / kN, 0, 5 * se);
  EXPECT_NEAR(s1 / kN, 0, 5 * se);
  EXPECT_NEAR(cs / kN, 0, 5 * se);
  EXPECT_NEAR(c2 / kN, 0.5, 5 * se);
  EXPECT_NEAR(c3 / kN, 0, 5 * se);
}

// A Henyey-Greenstein turn from a fixed direction: the mean new direction is g times the old one
// (the azimuth averages the sideways part away), and the mean square cosine is HG's second moment
// (1 + 2 g^2) / 3; from a direction near the pole as well as a general one.
TEST(ScatterHenyeyGreenstein, MeanDirectionAndSecondMoment) {
  for (const double g : {0.9, 0.4, -0.5, 0.0}) {
    const HenyeyGreenstein hg(g);
    for (const double uz0 : {0.36, -0.999999}) {
      const double ux0 = std::sqrt(1 - uz0 * uz0) * 0.6, uy0 = std::sqrt(1 - uz0 * uz0) * 0.8;
      Xoshiro256StarStar rng(5);
      constexpr int kN = 400000;
      double mx = 0, my = 0, mz = 0, m2 = 0;
      for (int n = 0; n < kN; ++n) {
        double ux = ux0, uy = uy0, uz = uz0;
        scatter_henyey_greenstein(hg, rng, ux, uy, uz);
        ASSERT_NEAR(ux * ux + uy * uy + uz * uz, 1, 1e-14);
        const double cosine = ux * ux0 + uy * uy0 + uz * uz0;
        mx += ux, my += uy, mz += uz, m2 += cosine * cosine;
      }
      const double se = 1 / std::sqrt(double(kN));  // each component's SD is below 1
      EXPECT_NEAR(mx / kN, g * ux0, 5 * se) << "g " << g << " uz " << uz0;
      EXPECT_NEAR(my / kN, g * uy0, 5 * se) << "g " << g << " uz " << uz0;
      EXPECT_NEAR(mz / kN, g * uz0, 5 * se) << "g " << g << " uz " << uz0;
      EXPECT_NEAR(m2 / kN, (1 + 2 * g * g) / 3, 5 * se) << "g " << g << " uz " << uz0;
    }
  }
}

}  // namespace
}  // namespace lucent::acquire::detail
