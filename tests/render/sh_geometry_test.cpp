// Tests of render/techniques/sh/sh_translucency.h, second part: the attenuation in the
// thickness (eq. 12 with its guard, and its integral over the plane) and the look-up geometry
// (refraction, the ray-box exit, the scaled box, the sphere's thickness). The basis, cube map,
// projection and irradiance are in sh_translucency_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "lucent/materials/medium.h"
#include "sh_translucency.h"

namespace lucent::render::sh {
namespace {

using Vec3d = Vec3<double>;

Vec3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Vec3d(normal(rng), normal(rng), normal(rng)).normalized();
}

materials::DiffusionCoefficients<double> medium(double sigma_a, double sigma_s_reduced) {
  return materials::derive_coefficients(
      materials::Medium<double>::from_reduced(sigma_a, sigma_s_reduced, 1.3));
}

void report(const std::string& what, double value) {
  std::cout << "[measured] " << what << ": " << value << "\n";
}

// sigma_a, sigma_s' in mm^-1 from Jensen et al. 2001's measured table: marble red, skin1 blue,
// ketchup green; and a medium that absorbs as much as it scatters (sigma_tr z_r = sqrt(3 / 2)).
const std::array<std::pair<double, double>, 4> kMedia{
    {{0.0021, 2.19}, {0.48, 1.01}, {0.97, 0.07}, {1.0, 1.0}}};

TEST(Attenuation, FiniteAndPositiveAtZeroThickness) {
  for (auto [sigma_a, sigma_s] : kMedia) {
    const auto c = medium(sigma_a, sigma_s);
    const double a0 = attenuation(0.0, c);
    ASSERT_TRUE(std::isfinite(a0));
    ASSERT_GT(a0, 0);
    const double s = c.sigma_tr * c.z_r;
    EXPECT_NEAR(a0, (s + 1) * std::exp(-s) * c.sigma_t_reduced * c.sigma_t_reduced, 1e-14 * a0);
    EXPECT_EQ(attenuation(-0.01, c), a0);  // negative thickness (depth noise) counts as 0
    EXPECT_TRUE(std::isinf(attenuation_seed(0.0, c.sigma_tr, c.sigma_t_reduced)));
  }
  EXPECT_EQ(attenuation(1.0, 0.5, 0.0), 0.0);  // no medium
}

// |ln(a / a_seed)| <= (z_r / d)^2 (3 + sigma_tr d) / 2, the bound the header derives: "(z_r / d)^2
// times a few" while sigma_tr d is a few, growing like sigma_tr z_r (z_r / d) beyond.
TEST(Attenuation, MatchesTheSeedFarFromTheSurface) {
  double tightness = 0, few = 0;
  for (auto [sigma_a, sigma_s] : kMedia) {
    const auto c = medium(sigma_a, sigma_s);
    for (double d_over_zr = 10; d_over_zr <= 1000; d_over_zr *= 1.25) {
      const double d = d_over_zr * c.z_r;
      if (c.sigma_tr * d > 700) break;  // e^(-700): both underflow toward 0 past 745
      const double a = attenuation(d, c);
      const double seed = attenuation_seed(d, c.sigma_tr, c.sigma_t_reduced);
      const double q = 1 / (d_over_zr * d_over_zr);
      const double bound = q * (3 + c.sigma_tr * d) / 2;
      const double dev = std::abs(std::log(a / seed));
      ASSERT_LE(dev, bound) << c.to_string() << " d=" << d;
      ASSERT_LT(a, seed);  // d_eff > d and a decreases
      tightness = std::max(tightness, dev / bound);
      if (c.sigma_tr * d <= 3) few = std::max(few, dev / q);
    }
  }
  report("attenuation: max |ln(a / a_seed)| / bound, d in [10, 1000] z_r", tightness);
  report("attenuation: max |ln(a / a_seed)| / (z_r / d)^2 where sigma_tr d <= 3", few);
  EXPECT_GT(tightness, 0.5);  // the bound is not loose by orders of magnitude
  EXPECT_LE(few, 3);
}

TEST(Attenuation, DecreasesWithThickness) {
  for (auto [sigma_a, sigma_s] : kMedia) {
    const auto c = medium(sigma_a, sigma_s);
    double previous = attenuation(0.0, c);
    for (int i = 1; i <= 2000; ++i) {
      const double a = attenuation(i * 0.01 * c.z_r, c);  // up to 20 z_r in steps of z_r / 100
      ASSERT_LT(a, previous) << c.to_string() << " step " << i;
      previous = a;
    }
  }
}

TEST(Attenuation, FloatTwinAgreesWithDouble) {
  const auto c = medium(0.032, 0.74);  // skin1 red
  double worst = 0;
  for (double d = 0; d < 20; d += 0.05) {
    const double a = attenuation(d, c.sigma_tr, c.sigma_t_reduced);
    const float af = attenuation(float(d), float(c.sigma_tr), float(c.sigma_t_reduced));
    worst = std::max(worst, std::abs(af / a - 1));
  }
  report("attenuation float vs double, max relative, d in [0, 20] mm", worst);
  EXPECT_LT(worst, 1e-5);  // exp of an argument up to ~5: a few ulps, 2e-6 relative at most
}

// ---- geometry -----------------------------------------------------------------------------------

TEST(Refract, FollowsSnellsLaw) {
  const Vec3d n(0, 0, 1);
  const double eta = 1.3;  // entering: eta_ratio = 1 / eta
  for (double theta = 0; theta < 1.5; theta += 0.05) {
    const Vec3d v(std::sin(theta), 0, -std::cos(theta));  // toward the surface
    const Vec3d t = refract(v, n, 1 / eta);
    ASSERT_NEAR(t.norm(), 1, 1e-14);
    EXPECT_LT(t.z(), 0);                               // into the object
    EXPECT_NEAR(t.x(), std::sin(theta) / eta, 1e-14);  // n1 sin(i) = n2 sin(t)
    EXPECT_NEAR(t.y(), 0, 1e-15);                      // in the plane of incidence
  }
}

TEST(Refract, TotalInternalReflectionGivesZero) {
  const Vec3d n(0, 0, 1);
  const double critical = std::asin(1 / 1.5);  // from inside glass toward air
  const Vec3d past(std::sin(critical + 0.01), 0, -std::cos(critical + 0.01));
  EXPECT_EQ(refract(past, n, 1.5), Vec3d::Zero());
  const Vec3d below(std::sin(critical - 0.01), 0, -std::cos(critical - 0.01));
  const Vec3d t = refract(below, n, 1.5);
  EXPECT_NEAR(t.norm(), 1, 1e-14);
  EXPECT_NEAR(t.x(), 1.5 * below.x(), 1e-14);  // Snell's law still, nearly grazing
}

TEST(RayBoxExit, ExitLiesOnTheBoxAndOnTheRay) {
  const Vec3d lo(-1, -0.5, 2), hi(3, 0.25, 2.5);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3d o = lo + (hi - lo).cwiseProduct(Vec3d(uniform(rng), uniform(rng), uniform(rng)));
    const Vec3d dir = random_direction(rng);
    const Vec3d p = ray_box_exit(lo, hi, o, dir);
    int on_faces = 0;
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(p[a], lo[a]);
      ASSERT_LE(p[a], hi[a]);
      on_faces += p[a] == lo[a] || p[a] == hi[a];
    }
    ASSERT_GE(on_faces, 1);                                       // exactly on a face plane
    ASSERT_GE((p - o).dot(dir), 0);                               // forward
    ASSERT_LT(((p - o) - (p - o).dot(dir) * dir).norm(), 1e-12);  // on the ray
  }
  EXPECT_EQ(ray_box_exit(lo, hi, Vec3d(0, 0, 2.2), Vec3d(0, 1, 0)), Vec3d(0, 0.25, 2.2));
  EXPECT_EQ(ray_box_exit(lo, hi, Vec3d(0, 0, 2.2), Vec3d::Zero().eval()), Vec3d(0, 0, 2.2));
  // An origin rounded just outside is clamped onto the box first.
  EXPECT_EQ(ray_box_exit(lo, hi, Vec3d(3 + 1e-12, 0, 2.2), Vec3d(-1, 0, 0)), Vec3d(-1, 0, 2.2));
}

TEST(BoxLookup, ScaledBoxFacesMapToCubeFaces) {
  const Vec3d lo(-1, -0.5, 2), hi(3, 0.25, 2.5);  // far from a cube
  const Vec3d centre = (lo + hi) / 2;
  EXPECT_NEAR((box_lookup_direction(lo, hi, hi) - Vec3d(1, 1, 1).normalized()).norm(), 0, 1e-15);
  // The +Y face of the box, anywhere on it, lands on the +Y face of the cube map.
  for (double fx : {0.05, 0.5, 0.95}) {
    for (double fz : {0.05, 0.5, 0.95}) {
      const Vec3d p(lo.x() + fx * (hi.x() - lo.x()), hi.y(), lo.z() + fz * (hi.z() - lo.z()));
      EXPECT_EQ(cube_coordinates(box_lookup_direction(lo, hi, p)).face, CubeFace::kPositiveY);
    }
  }
  // A flat box (zero z extent) ignores that axis.
  const Vec3d flat_hi(3, 0.25, 2);
  EXPECT_NEAR(box_lookup_direction(lo, flat_hi, Vec3d(3, centre.y(), 2)).x(), 1, 1e-15);
}

TEST(SphereThickness, IsTheChordOnTheFarSide) {
  const Vec3d c(1, -2, 0.5);
  const double R = 3;
  const Vec3d L = c + Vec3d(0.5, -1, -12);
  std::mt19937 rng(4);
  int far = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3d p = c + R * random_direction(rng);
    const double d = sphere_thickness(c, R, L, p);
    const Vec3d u = (p - L).normalized();
    const double b = (c - L).cross(u).norm();  // distance of the ray from the centre
    if ((p - c).dot(L - p) < 0) {              // the light sees the other side
      ++far;
      // 1e-9: rounding of the discriminant (~1e-14) through the sqrt near the silhouette.
      ASSERT_NEAR(d, 2 * std::sqrt(R * R - b * b), 1e-9) << "trial " << trial;
    } else {
      ASSERT_NEAR(d, 0, 1e-9);
    }
  }
  EXPECT_GT(far, 500);  // both sides exercised
  EXPECT_NEAR(sphere_thickness(c, R, Vec3d(c + Vec3d(0, 0, -10)), Vec3d(c + Vec3d(0, 0, R))), 2 * R,
              1e-12);
}

// attenuation_slab is eq. 12 integrated over the plane at distance d: held against a
// deterministic quadrature in rho (Simpson on a log grid out to where the kernel is 1e-16 of its
// peak) at d_eff, for several media and distances.
TEST(ShAttenuationSlab, EqualsEq12IntegratedOverThePlane) {
  for (const double sigma_tr : {0.05, 0.3, 2.0}) {
    for (const double sigma_t_reduced : {0.5, 2.0, 10.0}) {
      for (const double d : {0.0, 0.2, 1.0, 5.0}) {
        const double z_r = 1 / sigma_t_reduced;
        const double d_eff = std::sqrt(d * d + z_r * z_r);
        // rho = d_eff sinh(u): r = d_eff cosh(u), rho drho = r dr; integrate over u in [0, U].
        const int n = 20000;
        const double u_max = std::acosh(std::max(1.0, 40.0 / (sigma_tr * d_eff)));
        double sum = 0;
        for (int i = 0; i <= n; ++i) {
          const double u = u_max * i / n;
          const double r = d_eff * std::cosh(u), rho = d_eff * std::sinh(u);
          const double f = (sigma_tr * r + 1) * std::exp(-sigma_tr * r) /
                           (sigma_t_reduced * r * r * r) * 2 * M_PI * rho * d_eff * std::cosh(u);
          sum += f * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
        }
        const double quadrature = sum * u_max / n / 3;
        const double closed = attenuation_slab(d, sigma_tr, sigma_t_reduced);
        EXPECT_NEAR(closed, quadrature, 1e-7 * closed)
            << "sigma_tr " << sigma_tr << " sigma_t' " << sigma_t_reduced << " d " << d;
      }
    }
  }
  EXPECT_EQ(attenuation_slab(1.0, 0.3, 0.0), 0.0);
  EXPECT_TRUE(std::isfinite(attenuation_slab(-1.0, 0.3, 2.0)));
}

}  // namespace
}  // namespace lucent::render::sh
