// The semi-analytic form factor of Mertens et al. against quadratures that do not share its edge
// expansion: (1) polar about the pole, the radial integral analytic and the angular one by adaptive
// Gauss-Legendre to 1e-13 (what the issue asks for; only the exact r-integration is shared), and
// (2) a plain 2D cubature of R_d over the triangle (conical Gauss product rules on 4^5
// sub-triangles), which shares nothing but the dipole formula.
#include "lucent/render/hierarchical_form_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <numbers>
#include <vector>

#include "lucent/materials/dipole.h"
#include "lucent/materials/material.h"

namespace lucent::render::hierarchical {
namespace {

using Coefficients = materials::DiffusionCoefficients<double>;

Coefficients coefficients(const std::string& material, int channel) {
  return materials::derive_coefficients(materials::load_material(material).medium(channel));
}

// Gauss-Legendre, 10 points on [-1, 1].
constexpr std::array<double, 5> kNodes = {0.1488743389816312, 0.4333953941292472,
                                          0.6794095682990244, 0.8650633666889845,
                                          0.9739065285171717};
constexpr std::array<double, 5> kWeights = {0.2955242247147529, 0.2692667193099963,
                                            0.2190863625159820, 0.1494513471710756,
                                            0.0666713443086881};

double gauss10(const std::function<double(double)>& f, double a, double b) {
  const double m = 0.5 * (a + b), h = 0.5 * (b - a);
  double s = 0;
  for (std::size_t i = 0; i < kNodes.size(); ++i) {
    s += kWeights[i] * (f(m - h * kNodes[i]) + f(m + h * kNodes[i]));
  }
  return s * h;
}

double adaptive(const std::function<double(double)>& f, double a, double b, double whole,
                int depth = 0) {
  const double m = 0.5 * (a + b);
  const double left = gauss10(f, a, m), right = gauss10(f, m, b);
  if (depth > 40 || std::abs(left + right - whole) <= 1e-14 * std::abs(left + right) + 1e-300) {
    return left + right;
  }
  return adaptive(f, a, m, left, depth + 1) + adaptive(f, m, b, right, depth + 1);
}

// (1) Polar about the pole, per source: over each edge's wedge, z e^(-sigma H) / H dtheta minus
// z times the angular integral of e^(-sigma s(theta)) / s(theta), s the distance to the edge's point
// in direction theta; the angle integrated numerically.
double polar_form_factor(const Coefficients& c, const Vec3d& x_o, const Vec3d& n_o,
                         const std::array<Vec3d, 3>& tri, DipolePlacement placement) {
  const Vec3d normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
  const PlaneFrame plane = PlaneFrame::from_normal(tri[0], normal);
  PlaneSource sources[2];
  dipole_sources(c, x_o, n_o, plane, placement, sources);
  double sum = 0;
  for (const PlaneSource& src : sources) {
    for (int e = 0; e < 3; ++e) {
      const Vec2d a = plane.project(tri[std::size_t(e)]) - src.pole;
      const Vec2d b = plane.project(tri[std::size_t((e + 1) % 3)]) - src.pole;
      const double cross = a.x() * b.y() - a.y() * b.x();
      if (a.norm() == 0 || b.norm() == 0 || std::abs(cross) < 1e-15 * a.norm() * b.norm()) continue;
      const double dtheta = std::atan2(cross, a.dot(b));
      const Vec2d d = b - a;
      const double phi0 = std::atan2(a.y(), a.x());
      auto f = [&](double theta) {
        const Vec2d w(std::cos(phi0 + theta), std::sin(phi0 + theta));
        const double rho = (a.x() * d.y() - a.y() * d.x()) / (w.x() * d.y() - w.y() * d.x());
        const double s = std::sqrt(rho * rho + src.H * src.H);
        return std::exp(-c.sigma_tr * s) / s;
      };
      const double angular = adaptive(f, 0, dtheta, gauss10(f, 0, dtheta));
      sum += src.z * (std::exp(-c.sigma_tr * src.H) / src.H * dtheta - angular);
    }
  }
  return c.alpha_prime / (4 * std::numbers::pi) * sum;
}

// (2) R_d integrated over the triangle by brute force: 4^levels sub-triangles, each by a conical
// (collapsed-square) 10 x 10 Gauss product rule.
double cubature_form_factor(const Coefficients& c, const Vec3d& x_o, const Vec3d& n_o,
                            const std::array<Vec3d, 3>& tri, DipolePlacement placement,
                            int levels = 5) {
  std::vector<std::array<Vec3d, 3>> cells = {tri};
  for (int l = 0; l < levels; ++l) {
    std::vector<std::array<Vec3d, 3>> next;
    for (const auto& t : cells) {
      const Vec3d ab = 0.5 * (t[0] + t[1]), bc = 0.5 * (t[1] + t[2]), ca = 0.5 * (t[2] + t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    cells = std::move(next);
  }
  auto R_d = [&](const Vec3d& x) {
    return point_form_factor(c, x_o, n_o, x, 1.0, placement);
  };
  std::array<double, 10> node{}, weight{};
  for (std::size_t i = 0; i < 5; ++i) {
    node[i] = 0.5 * (1 - kNodes[i]);
    node[9 - i] = 0.5 * (1 + kNodes[i]);
    weight[i] = weight[9 - i] = 0.5 * kWeights[i];
  }
  double sum = 0;
  for (const auto& t : cells) {
    const double area2 = (t[1] - t[0]).cross(t[2] - t[0]).norm();
    for (std::size_t i = 0; i < 10; ++i)
      for (std::size_t j = 0; j < 10; ++j) {
        const double u = node[i], v = node[j];
        const Vec3d x = t[0] + u * (t[1] - t[0]) + u * v * (t[2] - t[1]);
        sum += weight[i] * weight[j] * u * area2 * R_d(x);
      }
  }
  return sum;
}

double relative(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The seed's Figure 3: a triangle with base 1 cm and height 0.5 cm, its tip at (x, 0) and its base
// beyond, x_o at the origin in the same plane; skim milk, every channel, a sweep of the tip distance.
TEST(HierarchicalFormFactor, SeedFigure3SweepAgainstPolarQuadrature) {
  const Vec3d x_o(0, 0, 0), n(0, 0, 1);
  const std::vector<double> tips = {0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20};
  FormFactorOptions seed;
  seed.rule = SegmentRule::kSeedMidpoint;
  seed.edge_constant = 0.4;
  FormFactorOptions tight = seed;
  tight.edge_constant = 0.1;
  const FormFactorOptions ours;  // gauss2, c = 2/5
  double worst_seed_near = 0, worst_seed = 0, worst_tight_near = 0, worst_tight = 0, worst_ours = 0;
  long seed_segments = 0, tight_segments = 0, ours_segments = 0;
  for (int ch = 0; ch < 3; ++ch) {
    const Coefficients c = coefficients("skimmilk", ch);
    for (double x : tips) {
      const std::array<Vec3d, 3> tri = {Vec3d(x, 0, 0), Vec3d(x + 5, -5, 0), Vec3d(x + 5, 5, 0)};
      const double truth = polar_form_factor(c, x_o, n, tri, DipolePlacement::kChord);
      FormFactorCounters cs, ct, co;
      const double f_seed = triangle_form_factor(c, x_o, n, tri[0], tri[1], tri[2], seed, &cs);
      const double f_tight = triangle_form_factor(c, x_o, n, tri[0], tri[1], tri[2], tight, &ct);
      const double f_ours = triangle_form_factor(c, x_o, n, tri[0], tri[1], tri[2], ours, &co);
      seed_segments += cs.segments;
      tight_segments += ct.segments;
      ours_segments += co.segments;
      const double e_seed = relative(f_seed, truth);
      if (x <= 2) worst_seed_near = std::max(worst_seed_near, e_seed);
      worst_seed = std::max(worst_seed, e_seed);
      worst_tight = std::max(worst_tight, relative(f_tight, truth));
      if (x <= 2) worst_tight_near = std::max(worst_tight_near, relative(f_tight, truth));
      worst_ours = std::max(worst_ours, relative(f_ours, truth));
      if (ch == 0 && (x == 0.1 || x == 2 || x == 20)) {
        std::printf("R tip %5.2f mm: F %.6e  seed %+.2f%%  c=0.1 %+.3f%%  gauss2 %+.4f%%\n", x, truth,
                    100 * (f_seed / truth - 1), 100 * (f_tight / truth - 1),
                    100 * (f_ours / truth - 1));
      }
    }
  }
  std::printf(
      "worst relative error over 3 channels x %zu tips: seed midpoint c=0.4 %.2f%% (tips <= 2 mm "
      "%.2f%%, %ld segments), midpoint c=0.1 %.3f%% (tips <= 2 mm %.3f%%, %ld segments), gauss2 "
      "c=0.4 %.4f%% (%ld segments)\n",
      tips.size(), 100 * worst_seed, 100 * worst_seed_near, seed_segments, 100 * worst_tight,
      100 * worst_tight_near, tight_segments, 100 * worst_ours, ours_segments);
  // The seed's rule, as the issue measured it, misses 1% near the tip (2.6-5.9% at tips <= 2 mm;
  // 20% at 20 mm, where I1 - I2 cancels to a small difference of large terms): the reason for the
  // options.
  EXPECT_GT(worst_seed_near, 0.01);
  // A tighter constant meets 1% near the tip at four times the segments (and still misses it at
  // 20 mm: 1.25%); the two-point rule meets 0.1% everywhere with the seed's constant and segments.
  EXPECT_LT(worst_tight_near, 0.01);
  EXPECT_LT(worst_ours, 1e-3);
  EXPECT_EQ(ours_segments, seed_segments);
}

// The polar quadrature itself against the brute-force cubature (they share only R_d).
TEST(HierarchicalFormFactor, PolarQuadratureAgreesWithPlainCubature) {
  const Coefficients c = coefficients("marble", 1);
  const Vec3d n(0, 0, 1);
  const std::array<Vec3d, 3> tri = {Vec3d(0.3, -0.2, 0), Vec3d(2.5, -1.0, 0), Vec3d(1.0, 2.0, 0)};
  for (const Vec3d& x_o : {Vec3d(0, 0, 0), Vec3d(1.1, 0.3, 0), Vec3d(1, 0.2, 1.5)}) {
    const double polar = polar_form_factor(c, x_o, n, tri, DipolePlacement::kChord);
    const double brute = cubature_form_factor(c, x_o, n, tri, DipolePlacement::kChord);
    EXPECT_LT(relative(polar, brute), 1e-6) << x_o.transpose();
  }
}

// Tilted triangles (H != z), both placements, each against both quadratures.
TEST(HierarchicalFormFactor, TiltedTrianglesBothPlacements) {
  const FormFactorOptions ours;
  for (const char* name : {"marble", "potato", "ketchup"}) {
    for (int ch = 0; ch < 3; ++ch) {
      const Coefficients c = coefficients(name, ch);
      const double l = 1.0 / c.sigma_t_reduced;  // mean free paths: the scale of the near field
      const Vec3d x_o(0, 0, 0), n_o(0, 0, 1);
      const double tilt = 40 * std::numbers::pi / 180;
      const Vec3d e1(1, 0, 0), e2(0, std::cos(tilt), std::sin(tilt));
      const Vec3d base(0.5 * l, 0.2 * l, -0.3 * l);
      const std::array<Vec3d, 3> tri = {base, base + 3 * l * e1, base + 2 * l * e2 + l * e1};
      for (DipolePlacement p : {DipolePlacement::kChord, DipolePlacement::kSeed3d}) {
        FormFactorOptions o = ours;
        o.placement = p;
        const double f = triangle_form_factor(c, x_o, n_o, tri[0], tri[1], tri[2], o);
        const double polar = polar_form_factor(c, x_o, n_o, tri, p);
        const double brute = cubature_form_factor(c, x_o, n_o, tri, p);
        EXPECT_LT(relative(f, polar), 1e-2) << name << ch << " " << to_string(p);
        EXPECT_LT(relative(polar, brute), 1e-5) << name << ch << " " << to_string(p);
      }
    }
  }
}

// The receiver's foot on an edge's line (R = 0), inside and outside the edge, and at a vertex.
TEST(HierarchicalFormFactor, PoleOnAnEdgeLineAndAtAVertex) {
  const Coefficients c = coefficients("potato", 0);
  const Vec3d n(0, 0, 1);
  const std::array<Vec3d, 3> tri = {Vec3d(0, 0, 0), Vec3d(3, 0, 0), Vec3d(1, 2, 0)};
  FormFactorOptions o;
  const std::vector<Vec3d> receivers = {
      Vec3d(0, 0, 0),     // at a vertex
      Vec3d(1.5, 0, 0),   // on an edge
      Vec3d(-1, 0, 0),    // on an edge's line, outside the edge
      Vec3d(1.5, 0, 0.7), // above an edge (H > z)
      Vec3d(1.0, 0.5, 0), // inside
  };
  for (const Vec3d& x_o : receivers) {
    const double f = triangle_form_factor(c, x_o, n, tri[0], tri[1], tri[2], o);
    const double brute = cubature_form_factor(c, x_o, n, tri, DipolePlacement::kChord);
    ASSERT_TRUE(std::isfinite(f)) << x_o.transpose();
    EXPECT_LT(relative(f, brute), 1e-2) << x_o.transpose();
  }
}

// Shared edges cancel: two triangles of a planar quad sum to the quad's four-edge form factor.
TEST(HierarchicalFormFactor, AdditiveAcrossASharedEdge) {
  const Coefficients c = coefficients("marble", 2);
  const FormFactorOptions o;
  const Vec3d a(0, 0, 0), b(4, -1, 0), d(5, 3, 0), e(-0.5, 2.5, 0), n(0, 0, 1);
  for (const Vec3d& x_o : {Vec3d(1, 1, 0), Vec3d(2.2, 0.9, 0.4), Vec3d(-3, 7, 0.1)}) {
    const double halves = triangle_form_factor(c, x_o, n, a, b, d, o) +
                          triangle_form_factor(c, x_o, n, a, d, e, o);
    const PlaneFrame plane = PlaneFrame::from_normal(a, n);
    const Vec2d p[4] = {plane.project(a), plane.project(b), plane.project(d), plane.project(e)};
    const Vec2d starts[4] = {p[0], p[1], p[2], p[3]}, ends[4] = {p[1], p[2], p[3], p[0]};
    const double quad = edges_form_factor(c, x_o, n, plane, starts, ends, o);
    EXPECT_LT(relative(halves, quad), 1e-12) << x_o.transpose();
  }
}

// A large flat tessellated plane gives B / E = R_tot, the dipole's total diffuse reflectance.
TEST(HierarchicalFormFactor, LargeTessellatedPlaneGivesTheTotalDiffuseReflectance) {
  const FormFactorOptions o;
  for (const char* name : {"marble", "potato", "skin1"}) {
    for (int ch = 0; ch < 3; ++ch) {
      const Coefficients c = coefficients(name, ch);
      const double half = 12 / c.sigma_tr;  // e^(-12): the plane's edge is far
      const int cells = 24;
      const Vec3d x_o(0.013 * half, -0.007 * half, 0), n(0, 0, 1);
      double sum = 0;
      for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
          const double x0 = -half + 2 * half * i / cells, x1 = -half + 2 * half * (i + 1) / cells;
          const double y0 = -half + 2 * half * j / cells, y1 = -half + 2 * half * (j + 1) / cells;
          sum += triangle_form_factor(c, x_o, n, Vec3d(x0, y0, 0), Vec3d(x1, y0, 0),
                                      Vec3d(x1, y1, 0), o) +
                 triangle_form_factor(c, x_o, n, Vec3d(x0, y0, 0), Vec3d(x1, y1, 0),
                                      Vec3d(x0, y1, 0), o);
        }
      const double R_tot = materials::dipole_total_reflectance(c.alpha_prime, c.A_dipole);
      EXPECT_LT(relative(sum, R_tot), 2e-4) << name << " " << ch << ": " << sum << " vs " << R_tot;
    }
  }
}

// The three channels in one pass give each channel's own value and counts, bit for bit: random
// pentagons (one concave) about receivers near and far, every rule, with and without the global
// condition, both placements, and a channel that does not scatter.
TEST(HierarchicalFormFactor, ThreeChannelsAtOnceEqualEachChannelAlone) {
  std::array<Coefficients, 3> black_green;
  for (int ch = 0; ch < 3; ++ch) black_green[std::size_t(ch)] = coefficients("marble", ch);
  black_green[1] = materials::derive_coefficients(
      materials::Medium<double>::from_reduced(1.0, 0.0, 1.3));  // sigma_s' 0: no scattering
  std::vector<std::array<Coefficients, 3>> materials_rgb = {black_green};
  for (const char* name : {"marble", "skimmilk", "ketchup"}) {
    std::array<Coefficients, 3> c;
    for (int ch = 0; ch < 3; ++ch) c[std::size_t(ch)] = coefficients(name, ch);
    materials_rgb.push_back(c);
  }
  const PlaneFrame plane = PlaneFrame::from_normal(Vec3d(0.1, -0.2, 0.3), Vec3d(0.2, -0.1, 1));
  std::uint64_t state = 12345;
  auto uniform = [&state] {  // a fixed LCG: the same polygons on every platform
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(1ull << 53);
  };
  long compared = 0;
  for (const auto& c : materials_rgb) {
    const double scale = 1 / c[0].sigma_tr;
    for (int polygon = 0; polygon < 12; ++polygon) {
      std::vector<Vec2d> starts, ends;
      const int n = 5;
      for (int k = 0; k < n; ++k) {
        const double angle = 2 * std::numbers::pi * (k + 0.8 * uniform()) / n;
        const double radius = scale * (k == 2 && polygon % 2 ? 0.2 : 0.5 + uniform());
        starts.push_back(Vec2d(radius * std::cos(angle), radius * std::sin(angle)));
      }
      for (int k = 0; k < n; ++k) ends.push_back(starts[std::size_t((k + 1) % n)]);
      const Vec3d x_o = plane.origin + scale * (3 * uniform() - 1.5) * plane.u +
                        scale * (3 * uniform() - 1.5) * plane.v +
                        scale * (polygon % 3 ? 0.5 * uniform() : 0.0) * plane.n;
      const Vec3d n_o = (plane.n + Vec3d(0.3 * uniform(), -0.2, 0.1)).normalized();
      for (const SegmentRule rule : {SegmentRule::kSeedMidpoint, SegmentRule::kGauss2})
        for (const bool global : {true, false})
          for (const DipolePlacement p : {DipolePlacement::kChord, DipolePlacement::kSeed3d}) {
            FormFactorOptions o;
            o.rule = rule;
            o.global_condition = global;
            o.placement = p;
            FormFactorCounters each, together;
            const std::array<double, 3> F =
                edges_form_factor_rgb(c, x_o, n_o, plane, starts, ends, o, &together);
            for (std::size_t ch = 0; ch < 3; ++ch) {
              EXPECT_EQ(F[ch], edges_form_factor(c[ch], x_o, n_o, plane, starts, ends, o, &each))
                  << polygon << " channel " << ch << " " << to_string(rule) << " " << to_string(p);
              ++compared;
            }
            EXPECT_EQ(together.calls, each.calls);
            EXPECT_EQ(together.segments, each.segments);
          }
    }
  }
  EXPECT_EQ(compared, 4 * 12 * 8 * 3);
}

TEST(HierarchicalFormFactor, FiniteAndZeroWhereItMustBe) {
  const Coefficients c = coefficients("ketchup", 2);
  const FormFactorOptions o;
  const Vec3d n(0, 0, 1), a(0, 0, 0), b(1, 0, 0), d(0, 1, 0);
  EXPECT_EQ(triangle_form_factor(c, Vec3d(0.2, 0.2, 0), n, a, b, a, o), 0.0);  // degenerate
  const double far = triangle_form_factor(c, Vec3d(1e4, 0, 0), n, a, b, d, o);
  EXPECT_TRUE(std::isfinite(far));
  EXPECT_GE(far, 0.0);
  EXPECT_LT(far, 1e-30);
  materials::Medium<double> black = materials::Medium<double>::from_reduced(1.0, 0.0, 1.3);
  const Coefficients none = materials::derive_coefficients(black);
  EXPECT_EQ(triangle_form_factor(none, Vec3d(0.2, 0.2, 0), n, a, b, d, o), 0.0);
}

}  // namespace
}  // namespace lucent::render::hierarchical
