// render/core/polygon_form_factor.h and area_light.h: the point-to-polygon form
// factor against closed forms from the radiation-heat-transfer catalogues (differential element to
// a parallel and to a perpendicular rectangle, coaxial disc), its symmetries, the point-light
// limit, the tangent-plane clip against brute-force quadrature, and the rect light's parsing and
// sampling.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "area_light.h"
#include "lucent/core/error.h"
#include "lucent/render/scene.h"
#include "polygon_form_factor.h"

namespace lucent::render {
namespace {

using V = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

double F(const std::vector<V>& p, const V& x = V::Zero(), const V& n = V::UnitZ(),
         bool clip = true) {
  return polygon_form_factor<double>(x, n, std::span<const V>(p), clip).F;
}

// The form factor by brute force: the clamped cosine kernel over a triangle's area (midpoint rule on
// a fine barycentric grid), for the clip test. Emitter cosine taken as |cos|, orientation by sign.
double triangle_quadrature(const V& a, const V& b, const V& c, const V& x, const V& n, int m) {
  const V normal = (b - a).cross(c - a);
  const double area = 0.5 * normal.norm();
  const V nl = normal.normalized();
  double sum = 0;
  int count = 0;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; i + j < m; ++j) {
      for (int k = 0; k < 2; ++k) {
        // Two sub-triangles per cell (up and down), centroids.
        if (k == 1 && i + j + 1 >= m) continue;
        const double u = (i + (k == 0 ? 1.0 / 3 : 2.0 / 3)) / m;
        const double v = (j + (k == 0 ? 1.0 / 3 : 2.0 / 3)) / m;
        const V p = a + u * (b - a) + v * (c - a);
        const V d = p - x;
        const double r2 = d.squaredNorm();
        const double cos_x = std::max(0.0, n.dot(d)) / std::sqrt(r2);
        const double cos_p = std::abs(nl.dot(d)) / std::sqrt(r2);
        sum += cos_x * cos_p / (kPi * r2);
        ++count;
      }
    }
  }
  return sum * area / count;
}

TEST(PolygonFormFactor, ParallelRectangleUnderTheCorner) {
  // a = 2, b = 3 at height c = 1.5 above the receiver, which lies under one corner:
  // F = (1 / 2 pi) [A / sqrt(1 + A^2) atan(B / sqrt(1 + A^2)) + B / sqrt(1 + B^2) atan(A /
  // sqrt(1 + B^2))], A = a / c, B = b / c (Howell's catalogue, B-3): 0.1880837.
  const double a = 2, b = 3, c = 1.5;
  const double A = a / c, B = b / c;
  const double closed = (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
                         B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B))) /
                        (2 * kPi);
  EXPECT_NEAR(closed, 0.1880837, 1e-7);
  // Wound so that the winding normal points down, toward the receiver (its emitting side).
  EXPECT_NEAR(F({V(0, 0, c), V(0, b, c), V(a, b, c), V(a, 0, c)}), 0.1880837, 1e-7);
}

TEST(PolygonFormFactor, PerpendicularRectangle) {
  // A rectangle of width 2 and height 1 standing on the receiver's plane at distance 1.3, the
  // receiver opposite one of its bottom corners: F = (1 / 2 pi) [atan(1 / Y) - Y / sqrt(X^2 + Y^2)
  // atan(1 / sqrt(X^2 + Y^2))], X = h / w, Y = d / w (Howell B-2): 0.0467577.
  const double w = 2, h = 1, d = 1.3;
  const double X = h / w, Y = d / w, Z = std::sqrt(X * X + Y * Y);
  const double closed = (std::atan(1 / Y) - Y / Z * std::atan(1 / Z)) / (2 * kPi);
  EXPECT_NEAR(closed, 0.0467577, 1e-7);
  EXPECT_NEAR(F({V(d, 0, 0), V(d, 0, h), V(d, w, h), V(d, w, 0)}), 0.0467577, 1e-7);
}

TEST(PolygonFormFactor, CoaxialDiscAsA4000Gon) {
  // F = R^2 / (R^2 + h^2) for a disc of radius R at height h; the inscribed 4000-gon has area
  // (4000 / 2 pi) sin(2 pi / 4000) of the disc's, so it is scaled to the disc's area first.
  const int N = 4000;
  const double R = 1.7, h = 0.9;
  const double scale = std::sqrt(2 * kPi / (N * std::sin(2 * kPi / N)));
  std::vector<V> p;
  for (int i = 0; i < N; ++i) {
    const double phi = -2 * kPi * i / N;  // clockwise seen from above: normal down
    p.emplace_back(R * scale * std::cos(phi), R * scale * std::sin(phi), h);
  }
  EXPECT_NEAR(F(p), R * R / (R * R + h * h), 1e-7);
  // And the 8-gon through the function agrees with the same sum.
  std::vector<V> octagon;
  for (int i = 0; i < 8; ++i) {
    const double phi = -2 * kPi * i / 8;
    octagon.emplace_back(R * std::cos(phi), R * std::sin(phi), h);
  }
  const double area8 = 0.5 * 8 * R * R * std::sin(2 * kPi / 8);
  const double f8 = F(octagon);
  EXPECT_GT(f8, 0);
  EXPECT_LT(f8, R * R / (R * R + h * h));               // inscribed: less than the disc
  EXPECT_GT(f8, area8 / (kPi * R * R) * R * R / (R * R + h * h) * 0.95);
}

TEST(PolygonFormFactor, WindingSymmetryAndMotion) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    // A random convex quad above the receiver (a parallelogram), random tilt.
    const V c(u(rng), u(rng), 1.5 + u(rng));
    const V a(u(rng), u(rng), 0.3 * u(rng)), b(u(rng), u(rng), 0.3 * u(rng));
    std::vector<V> q = {c - a - b, c + a - b, c + a + b, c - a + b};
    const V n = V(0.3 * u(rng), 0.3 * u(rng), 1).normalized();
    const double f = F(q, V::Zero(), n);
    std::vector<V> reversed(q.rbegin(), q.rend());
    EXPECT_NEAR(F(reversed, V::Zero(), n), -f, 1e-12);
    std::vector<V> shifted = {q[2], q[3], q[0], q[1]};
    EXPECT_NEAR(F(shifted, V::Zero(), n), f, 1e-12);
    // Rigid motion of receiver and polygon together.
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(u(rng) * kPi, V(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    const V t(10 * u(rng), 10 * u(rng), 10 * u(rng));
    std::vector<V> moved;
    for (const V& p : q) moved.push_back(R * p + t);
    EXPECT_NEAR(F(moved, t, R * n), f, 1e-11);
    // n . vector = F.
    const auto full = polygon_form_factor<double>(V::Zero(), n, std::span<const V>(q));
    EXPECT_NEAR(n.dot(full.vector), full.F, 1e-14);
  }
}

TEST(PolygonFormFactor, BackFacingReceiverGetsNothing) {
  // The polygon entirely below the receiver's tangent plane is clipped away: 0, for either winding.
  const std::vector<V> q = {V(-1, -1, -2), V(-1, 1, -2), V(1, 1, -2), V(1, -1, -2)};
  EXPECT_EQ(F(q), 0.0);
  EXPECT_EQ(F({q[3], q[2], q[1], q[0]}), 0.0);
  // Without the clip the contour sum counts it with the cosine's sign.
  EXPECT_LT(std::abs(F(q, V::Zero(), V::UnitZ(), false)), 1.0);
  EXPECT_NE(F(q, V::Zero(), V::UnitZ(), false), 0.0);
}

TEST(PolygonFormFactor, TinyQuadIsAPointLight) {
  // pi L F -> L A cos_p cos_x / d^2 as the quad shrinks: a point light of intensity L A cos_p.
  const V centre(0.7, -0.4, 2.0);
  const V n = V(0.2, 0.1, 1).normalized();
  for (double half : {1e-2, 1e-3}) {
    const V u = half * V(1, 0, 0.3).normalized(), v = half * V(0, 1, -0.2).normalized();
    // Winding normal u x v points up; emit downward by winding v before u.
    const std::vector<V> q = {centre - u - v, centre - u + v, centre + u + v, centre + u - v};
    const V normal = -(u.cross(v)).normalized();
    const double A = 4 * u.cross(v).norm();
    const V d = centre;  // from the receiver at the origin
    const double r2 = d.squaredNorm();
    const double point = A * (-normal.dot(d) / std::sqrt(r2)) * (n.dot(d) / std::sqrt(r2)) / r2;
    EXPECT_NEAR(kPi * F(q, V::Zero(), n) / point, 1.0, 5 * half * half);
  }
}

TEST(PolygonFormFactor, StraddlingTriangleNeedsTheClip) {
  // A triangle crossing the receiver's horizon: the clipped contour sum equals the quadrature of
  // the clamped cosine; the seed's unclipped sum is the integral of the signed cosine, which is
  // off by more than 2% here.
  const V a(2, -1, -0.6), b(2, 1, -0.6), c(1.6, 0, 1.4);
  const V x = V::Zero(), n = V::UnitZ();
  const std::vector<V> tri = {a, c, b};  // winding normal toward the receiver (-x side)
  const double clipped = F(tri, x, n), unclipped = F(tri, x, n, false);
  const double quadrature = triangle_quadrature(a, b, c, x, n, 600);
  EXPECT_NEAR(clipped / quadrature, 1.0, 2e-4);
  EXPECT_GT(std::abs(unclipped / quadrature - 1.0), 0.02);
}

TEST(AreaLight, RectParsesAndSamplesUniformly) {
  const Light light = parse_light("rect:0,50,0:20,0,0:0,0,-10:2,2,2");
  EXPECT_EQ(light.type, LightType::kArea);
  ASSERT_EQ(light.polygon.size(), 4u);
  // U x V = (20,0,0) x (0,0,-10) = (0, 200, 0): emits up (+y).
  EXPECT_NEAR(area_light_normal(light).y(), 1.0, 1e-6);
  EXPECT_NEAR(area_light_area(light), 800.0, 1e-3);
  EXPECT_NEAR((area_light_centroid(light) - Vec3f(0, 50, 0)).norm(), 0.0, 1e-5);
  // Uniform by area: the mean of a stratified grid is the centroid, the second moment that of a
  // uniform rect (x^2: a^2 / 3 with a = 20).
  double mx = 0, mxx = 0;
  const int n = 64;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Vec3f p = area_light_point(light, (i + 0.5) / n, (j + 0.5) / n);
      mx += p.x();
      mxx += double(p.x()) * p.x();
      EXPECT_NEAR(p.y(), 50.0f, 1e-4f);
    }
  }
  EXPECT_NEAR(mx / (n * n), 0.0, 0.05);
  EXPECT_NEAR(mxx / (n * n) / (400.0 / 3.0), 1.0, 0.01);
  // The irradiance of a point facing the rect is pi L F from its emitting side, 0 from behind.
  const std::array<Eigen::Vector3d, 4> q = {
      light.polygon[0].cast<double>(), light.polygon[1].cast<double>(),
      light.polygon[2].cast<double>(), light.polygon[3].cast<double>()};
  EXPECT_GT(polygon_form_factor<double>(V(0, 60, 0), V(0, -1, 0), q).F, 0.0);
  EXPECT_LT(polygon_form_factor<double>(V(0, 40, 0), V(0, 1, 0), q).F, 0.0);
}

TEST(AreaLight, BadRectsAreRefusedWithTheField) {
  for (const char* bad : {"rect:0,0,0:1,0,0:2,0,0:1,1,1", "rect:0,0,0:0,0,0:0,1,0:1,1,1",
                          "rect:0,0,0:1,0,0:0,1,0", "rect:0,0,0:1,0,0:0,1,0:-1,1,1",
                          "rect:0,0,x:1,0,0:0,1,0:1,1,1", "rect:0,0,0:1,0,0:0,nan,0:1,1,1"}) {
    try {
      (void)parse_light(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--light"), std::string::npos) << e.what();
    }
  }
  // Non-planar and non-convex polygons through the API.
  EXPECT_THROW((void)area_light({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, 0}}, {1, 1, 1}),
               Error);
  EXPECT_THROW((void)area_light({{0, 0, 0}, {2, 0, 0}, {0.5f, 0.5f, 0}, {0, 2, 0}}, {1, 1, 1}),
               Error);
  const auto lights = triangle_lights({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}},
                                      {{0, 1, 2}, {1, 3, 2}}, {1, 1, 1});
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_NEAR(area_light_area(lights[0]) + area_light_area(lights[1]), 1.0, 1e-6);
}

}  // namespace
}  // namespace lucent::render
