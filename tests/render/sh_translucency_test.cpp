// Tests of render/techniques/sh/sh_translucency.h: the SH basis, cube-map texel weights and
// directions, projection and the irradiance matrix of the
// spherical-harmonics fast translucency technique (Banterle and Chalmers 2006, Banterle &
// Chalmers); the attenuation and look-up geometry are in sh_geometry_test.cpp.
#include "sh_translucency.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "lucent/materials/medium.h"

namespace lucent::render::sh {
namespace {

constexpr double kPi = std::numbers::pi;
using Vec3d = Vec3<double>;

Vec3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Vec3d(normal(rng), normal(rng), normal(rng)).normalized();
}

Coefficients<double> random_coefficients(std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  Coefficients<double> e;
  for (double& c : e) c = uniform(rng);
  return e;
}

double max_abs(const Coefficients<double>& e, std::initializer_list<int> except) {
  double m = 0;
  for (int k = 0; k < kCoefficientCount; ++k) {
    if (std::find(except.begin(), except.end(), k) == except.end()) m = std::max(m, std::abs(e[k]));
  }
  return m;
}

void report(const std::string& what, double value) {
  std::cout << "[measured] " << what << ": " << value << "\n";
}

// ---- basis --------------------------------------------------------------------------------------

TEST(ShBasis, ConstantsAreTheExactFormsOfRamamoorthiHanrahan) {
  const BasisConstants k = basis_constants();
  // R&H print six digits: each exact value must round to them.
  EXPECT_NEAR(k.y00, 0.282095, 5e-7);
  EXPECT_NEAR(k.y1, 0.488603, 5e-7);
  EXPECT_NEAR(k.y2, 1.092548, 5e-7);
  EXPECT_NEAR(k.y20, 0.315392, 5e-7);
  EXPECT_NEAR(k.y22, 0.546274, 5e-7);
  EXPECT_DOUBLE_EQ(k.y00 * k.y00 * 4 * kPi, 1.0);
  EXPECT_DOUBLE_EQ(k.y22 * 2, k.y2);
}

// The seed's eq. 7-9 with P_l^|m| for both signs of m and no Condon-Shortley phase, in spherical
// coordinates, written out independently of the polynomial form.
TEST(ShBasis, MatchesTheSphericalDefinitionWithoutCondonShortleyPhase) {
  const auto K = [](int l, int m) {
    const int am = std::abs(m);
    double ratio = 1;  // (l - |m|)! / (l + |m|)!
    for (int i = l - am + 1; i <= l + am; ++i) ratio /= i;
    return std::sqrt((2 * l + 1) * ratio / (4 * kPi));
  };
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3d s = random_direction(rng);
    const double ct = s.z(), st = std::sqrt(1 - ct * ct), phi = std::atan2(s.y(), s.x());
    const double P[3][3] = {
        {1, 0, 0}, {ct, st, 0}, {(3 * ct * ct - 1) / 2, 3 * ct * st, 3 * st * st}};
    const auto y = sh_basis(s);
    for (int l = 0; l < kBandCount; ++l) {
      for (int m = -l; m <= l; ++m) {
        const int am = std::abs(m);
        const double azimuth = m > 0 ? std::cos(am * phi) : std::sin(am * phi);
        const double expected =
            m == 0 ? K(l, 0) * P[l][0] : std::sqrt(2.0) * K(l, m) * P[l][am] * azimuth;
        ASSERT_NEAR(y[sh_index(l, m)], expected, 1e-13) << "l=" << l << " m=" << m;  // rounding
      }
    }
  }
  // Without the phase Y11 is positive along +x, Y1-1 along +y.
  EXPECT_GT(sh_basis(1.0, 0.0, 0.0)[sh_index(1, 1)], 0);
  EXPECT_GT(sh_basis(0.0, 1.0, 0.0)[sh_index(1, -1)], 0);
}

TEST(ShBasis, IsOrthonormalUnderExactQuadrature) {
  // Gram matrix by the cube map with exact texel solid angles: the midpoint rule in the integrand
  // still errs by O(W^-2), measured 2.5e-5 at W = 128; bound 1e-4.
  double worst = 0;
  std::array<std::array<double, 9>, 9> gram{};
  for_each_cube_texel<double>(128, TexelWeight::kExact,
                              [&](CubeFace, int, int, const Vec3d& w, double d_omega) {
                                const auto y = sh_basis(w);
                                for (int a = 0; a < 9; ++a)
                                  for (int b = 0; b < 9; ++b) gram[a][b] += y[a] * y[b] * d_omega;
                              });
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) worst = std::max(worst, std::abs(gram[a][b] - (a == b)));
  report("basis Gram matrix max |G - I|, W = 128", worst);
  EXPECT_LT(worst, 1e-4);
}

// ---- cube map -----------------------------------------------------------------------------------

TEST(CubeMap, DirectionsFollowTheOpenGlFaceTable) {
  // The specification's table: +X sc = -rz, tc = -ry; +Y sc = +rx, tc = +rz; -Z sc = -rx, tc = -ry.
  const auto expect_at = [](const Vec3d& r, CubeFace face, double u, double v) {
    const auto c = cube_coordinates(r);
    EXPECT_EQ(c.face, face) << r.transpose();
    EXPECT_NEAR(c.u, u, 1e-15) << r.transpose();
    EXPECT_NEAR(c.v, v, 1e-15) << r.transpose();
  };
  expect_at(Vec3d(1, 0.5, 0.25).normalized(), CubeFace::kPositiveX, -0.25, -0.5);
  expect_at(Vec3d(0.2, 1, -0.6), CubeFace::kPositiveY, 0.2, -0.6);
  expect_at(Vec3d(0.2, -0.3, -1), CubeFace::kNegativeZ, -0.2, 0.3);
  // Texel (0, 0) of +X is at s, t near 0: sc < 0 so z > 0, tc < 0 so y > 0.
  const Vec3d t00 = cube_texel_direction<double>(CubeFace::kPositiveX, 0, 0, 4);
  EXPECT_GT(t00.z(), 0);
  EXPECT_GT(t00.y(), 0);
}

TEST(CubeMap, TexelDirectionsRoundTripThroughFaceSelection) {
  constexpr int W = 16;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const auto face = static_cast<CubeFace>(f);
    EXPECT_NEAR(cube_face_point(face, 0.0, 0.0).norm(), 1.0, 0);  // face centre on the major axis
    for (int j = 0; j < W; ++j) {
      for (int i = 0; i < W; ++i) {
        const Vec3d d = cube_texel_direction<double>(face, i, j, W);
        ASSERT_NEAR(d.norm(), 1.0, 1e-15);
        const auto c = cube_coordinates(d);
        ASSERT_EQ(c.face, face) << "face " << f << " texel " << i << "," << j;
        ASSERT_NEAR(c.u, texel_centre_coordinate<double>(i, W), 1e-14);
        ASSERT_NEAR(c.v, texel_centre_coordinate<double>(j, W), 1e-14);
      }
    }
  }
}

double solid_angle_sum(int W, TexelWeight weight) {
  double sum = 0;
  for_each_cube_texel<double>(
      W, weight, [&](CubeFace, int, int, const Vec3d&, double d_omega) { sum += d_omega; });
  return sum;
}

TEST(CubeMap, TexelWeightsSumToFourPi) {
  const double exact64 = solid_angle_sum(64, TexelWeight::kExact);
  const double approx64 = solid_angle_sum(64, TexelWeight::kDifferential);
  const double approx128 = solid_angle_sum(128, TexelWeight::kDifferential);
  const double err64 = approx64 / (4 * kPi) - 1, err128 = approx128 / (4 * kPi) - 1;
  report("exact texel solid angles, W = 64: sum - 4 pi", exact64 - 4 * kPi);
  report("differential texel weights, W = 64: sum / 4 pi - 1", err64);
  report("differential texel weights, W = 128: sum / 4 pi - 1", err128);
  EXPECT_NEAR(exact64, 4 * kPi, 1e-12);  // telescoping atan2 differences: rounding only
  // Midpoint rule: measured +6.0e-5 at W = 64 (an overestimate).
  EXPECT_LT(std::abs(err64), 1e-4);
  EXPECT_GT(err64, 0);
  // Second order: halving the texel quarters the error (ratio 4 up to O(W^-2) terms).
  EXPECT_NEAR(err64 / err128, 4.0, 0.1);
  EXPECT_NEAR(solid_angle_sum(1, TexelWeight::kExact), 4 * kPi, 1e-13);  // one texel a face
}

TEST(CubeMap, DifferentialWeightApproachesTheExactSolidAngle) {
  constexpr int W = 64;
  double worst = 0;
  for (int j = 0; j < W; ++j) {
    for (int i = 0; i < W; ++i) {
      const double exact = texel_solid_angle<double>(i, j, W);
      ASSERT_GT(exact, 0);
      worst = std::max(worst, std::abs(texel_weight<double>(i, j, W) / exact - 1));
    }
  }
  report("per-texel |weight / solid angle - 1|, W = 64, max", worst);
  // The midpoint rule's relative error per texel is (h^2 / 24) |w_uu + w_vv| / w: h^2 / 4 = 2.4e-4
  // at the face centre (h = 2 / W), the measured maximum; bound 4e-4.
  EXPECT_LT(worst, 4e-4);
}

TEST(CubeMap, RejectsAnEmptyFace) {
  EXPECT_THROW(for_each_cube_texel<double>(0, TexelWeight::kExact,
                                           [](CubeFace, int, int, const Vec3d&, double) {}),
               lucent::Error);
}

// ---- projection ---------------------------------------------------------------------------------

TEST(Projection, ConstantProjectsToBandZeroOnly) {
  const double c = 2.5;
  const auto e = project_cube_channel<double>([&](const Vec3d&) { return c; }, 64);
  const double rel = e[0] / (c * std::sqrt(4 * kPi)) - 1;
  report("constant: E00 / (c sqrt(4 pi)) - 1, W = 64", rel);
  report("constant: max |E_lm|, lm != 00, / E00", max_abs(e, {0}) / e[0]);
  // E00 = c Y00 sum(dOmega): exactly the weight-sum error (6.0e-5 measured above).
  EXPECT_LT(std::abs(rel), 1e-4);
  // The cube's symmetries cancel bands 1 and 2 exactly, up to rounding in 24576 terms.
  EXPECT_LT(max_abs(e, {0}), 1e-12 * e[0]);
  // With exact solid angles the constant is integrated to rounding.
  const auto exact =
      project_cube_channel<double>([&](const Vec3d&) { return c; }, 64, TexelWeight::kExact);
  EXPECT_NEAR(exact[0], c * std::sqrt(4 * kPi), 1e-12);
}

TEST(Projection, LinearProjectsToBandOneOnly) {
  const double a = 0.7, b = -1.3, c = 0.4;
  const auto e = project_cube_channel<double>(
      [&](const Vec3d& w) { return a * w.x() + b * w.y() + c * w.z(); }, 64);
  const double s = std::sqrt(4 * kPi / 3);  // integral of (k1 y) y over the sphere
  double worst = 0;
  for (auto [k, expected] :
       {std::pair{sh_index(1, -1), b * s}, {sh_index(1, 0), c * s}, {sh_index(1, 1), a * s}}) {
    worst = std::max(worst, std::abs(e[k] / expected - 1));
  }
  report("linear: max |E1m / exact - 1|, W = 64", worst);
  report("linear: max |E_lm|, l != 1", max_abs(e, {1, 2, 3}));
  EXPECT_LT(worst, 1e-4);                   // measured 6.0e-5: by symmetry sum w x^2 = sum w / 3
  EXPECT_LT(max_abs(e, {1, 2, 3}), 1e-12);  // odd integrands over a symmetric cube: rounding
}

TEST(Projection, QuadraticProjectsToBandsZeroAndTwo) {
  // x^2 + 2 y z + 1/2 = 5/6 + (x^2 - y^2)/2 - (3 z^2 - 1)/6 + 2 yz on the unit sphere.
  const BasisConstants k = basis_constants();
  const auto e = project_cube_channel<double>(
      [](const Vec3d& w) { return w.x() * w.x() + 2 * w.y() * w.z() + 0.5; }, 64);
  Coefficients<double> expected{};
  expected[sh_index(0, 0)] = 5.0 / 6.0 * std::sqrt(4 * kPi);
  expected[sh_index(2, 2)] = 0.5 / k.y22;
  expected[sh_index(2, 0)] = -1.0 / (6.0 * k.y20);
  expected[sh_index(2, -1)] = 2.0 / k.y2;
  double worst = 0;
  for (int i : {sh_index(0, 0), sh_index(2, 2), sh_index(2, 0), sh_index(2, -1)})
    worst = std::max(worst, std::abs(e[i] / expected[i] - 1));
  report("quadratic: max |E_lm / exact - 1| over bands 0 and 2, W = 64", worst);
  report("quadratic: max |E_lm| where exact is 0", max_abs(e, {0, 5, 6, 8}));
  EXPECT_LT(worst, 2e-4);                      // measured 9.0e-5
  EXPECT_LT(max_abs(e, {0, 5, 6, 8}), 1e-12);  // symmetry: rounding only
}

// A von Mises-Fisher lobe of concentration kappa, normalised to unit integral, has the analytic
// coefficients lambda_l Y_lm(w0): lambda_0 = 1, lambda_1 = coth(kappa) - 1/kappa,
// lambda_2 = 1 - 3 lambda_1 / kappa.
struct Lobe {
  Vec3d w0;
  double kappa;
  double operator()(const Vec3d& w) const {
    return kappa / (2 * kPi * (1 - std::exp(-2 * kappa))) * std::exp(kappa * (w.dot(w0) - 1));
  }
  std::array<double, 3> lambda() const {
    const double l1 = 1 / std::tanh(kappa) - 1 / kappa;
    return {1.0, l1, 1 - 3 * l1 / kappa};
  }
};

double lobe_coefficient_error(const Lobe& lobe, int W) {
  const auto e = project_cube_channel<double>(lobe, W);
  const auto y = sh_basis(lobe.w0);
  const auto lambda = lobe.lambda();
  double worst = 0;
  for (int l = 0; l < kBandCount; ++l)
    for (int m = -l; m <= l; ++m)
      worst = std::max(worst, std::abs(e[sh_index(l, m)] - lambda[l] * y[sh_index(l, m)]));
  return worst;
}

const Lobe kFaceLobe{Vec3d(0.3, -0.5, 0.8).normalized(), 50.0};  // inside the +Z face
const Lobe kCornerLobe{Vec3d(0.6, 0.6, -0.52).normalized(),
                       50.0};  // on the +X/+Y seam, near a corner

TEST(Projection, NarrowLobeMatchesItsAnalyticCoefficients) {
  const double face = lobe_coefficient_error(kFaceLobe, 64);
  const double corner = lobe_coefficient_error(kCornerLobe, 64);
  report("vMF lobe kappa = 50 in a face: max |E_lm - exact|, W = 64", face);
  report("vMF lobe kappa = 50 at a corner: max |E_lm - exact|, W = 64", corner);
  // The lobe's standard deviation (1 / sqrt(50) rad) spans 3-5 texels: measured 2.0e-5 (face) and
  // 1.2e-4 (across the face seams).
  EXPECT_LT(face, 1e-4);
  EXPECT_LT(corner, 2e-4);
  EXPECT_LT(lobe_coefficient_error(kCornerLobe, 128), corner / 3);  // second order
}

TEST(Projection, RgbIsThreeChannelProjections) {
  const Lobe lobe{Vec3d(-0.6, 0.1, -0.2).normalized(), 8.0};
  const auto rgb = project_cube<double>(
      [&](const Vec3d& w) {
        return std::array<double, 3>{lobe(w), 2.0, w.x() * w.y()};
      },
      16);
  const auto r = project_cube_channel<double>(lobe, 16);
  const auto g = project_cube_channel<double>([](const Vec3d&) { return 2.0; }, 16);
  const auto b = project_cube_channel<double>([](const Vec3d& w) { return w.x() * w.y(); }, 16);
  for (int k = 0; k < kCoefficientCount; ++k) {
    EXPECT_DOUBLE_EQ(rgb[0][k], r[k]);  // same sums in the same order
    EXPECT_DOUBLE_EQ(rgb[1][k], g[k]);
    EXPECT_DOUBLE_EQ(rgb[2][k], b[k]);
  }
}

// ---- irradiance ---------------------------------------------------------------------------------

TEST(Irradiance, ConstantsAreTheExactFormsOfTheRoundedOnes) {
  const IrradianceConstants c = irradiance_constants();
  const BasisConstants k = basis_constants();
  const auto A = cosine_lobe_factors<double>();
  EXPECT_DOUBLE_EQ(c.c1, A[2] * k.y22);
  EXPECT_DOUBLE_EQ(c.c2, A[1] * k.y1 / 2);
  EXPECT_DOUBLE_EQ(c.c3, 3 * A[2] * k.y20);
  EXPECT_DOUBLE_EQ(c.c4, A[0] * k.y00);
  EXPECT_DOUBLE_EQ(c.c5, A[2] * k.y20);
  // The printed c1..c5 match products of the six-digit basis constants: c2 and c3 are 0.7e-6 and
  // 1.1e-6 off the exact values, so the printed digits agree only to 2e-6.
  EXPECT_NEAR(c.c1, 0.429043, 2e-6);
  EXPECT_NEAR(c.c2, 0.511664, 2e-6);
  EXPECT_NEAR(c.c3, 0.743125, 2e-6);
  EXPECT_NEAR(c.c4, 0.886227, 2e-6);
  EXPECT_NEAR(c.c5, 0.247708, 2e-6);
}

TEST(Irradiance, MatrixIsSymmetricAndItsQuadraticFormIsTheSum) {
  std::mt19937 rng(12);
  double worst = 0;
  for (int set = 0; set < 100; ++set) {
    const auto e = random_coefficients(rng);
    const Mat4<double> m = irradiance_matrix(e);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) ASSERT_EQ(m(a, b), m(b, a));  // exactly: same products
    for (int d = 0; d < 100; ++d) {
      const Vec3d n = random_direction(rng);
      worst = std::max(worst, std::abs(irradiance(m, n) - irradiance_from_coefficients(e, n)));
    }
  }
  report("|r^T M r - sum A_l E_lm Y_lm| max, |E_lm| <= 1", worst);
  EXPECT_LT(worst, 1e-13);  // O(1) terms summed in double: rounding only
}

TEST(Irradiance, SeedRowFourAsPrintedIsNotTheIrradiance) {
  // Eq. 11 prints row 4 as (c1 E11, c2 E2-1, ...): that matrix is not symmetric and its quadratic
  // form is not R&H's sum, which is why we use (c2 E11, c2 E1-1, ...).
  Coefficients<double> e{};
  e[sh_index(1, 1)] = 1;
  e[sh_index(2, -1)] = 1;
  Mat4<double> printed = irradiance_matrix(e);
  const IrradianceConstants c = irradiance_constants();
  printed(3, 0) = c.c1 * e[sh_index(1, 1)];
  printed(3, 1) = c.c2 * e[sh_index(2, -1)];
  const Vec3d n = Vec3d(1, 1, 1).normalized();
  EXPECT_GT(std::abs(irradiance(printed, n) - irradiance_from_coefficients(e, n)), 0.05);
}

TEST(Irradiance, FloatTwinAgreesWithDouble) {
  std::mt19937 rng(5);
  double worst = 0;
  for (int set = 0; set < 50; ++set) {
    const auto e = random_coefficients(rng);
    Coefficients<float> ef;
    for (int k = 0; k < 9; ++k) ef[k] = float(e[k]);
    const Mat4<double> m = irradiance_matrix(e);
    const Mat4<float> mf = irradiance_matrix(ef);
    for (int d = 0; d < 50; ++d) {
      const Vec3d n = random_direction(rng);
      worst = std::max(worst,
                       std::abs(irradiance(mf, Vec3<float>(n.cast<float>())) - irradiance(m, n)));
    }
  }
  report("float vs double r^T M r, max abs, |E_lm| <= 1", worst);
  EXPECT_LT(worst, 1e-5);  // ~16 float products of O(1): a few ulps (6e-8) each
}

// A directional light w0 has E_lm = Y_lm(w0). By Funk-Hecke its 9-term irradiance is
// sum_l A_l (2l+1)/(4 pi) P_l(c) = 3/32 + c/2 + 15/32 c^2 with c = n . w0, against max(0, c).
TEST(Irradiance, DirectionalLightGivesTheKnownNineTermCosineError) {
  const Vec3d w0 = Vec3d(-0.2, 0.9, 0.4).normalized();
  const auto y0 = sh_basis(w0);
  Coefficients<double> e;
  std::copy(y0.begin(), y0.end(), e.begin());
  const Mat4<double> m = irradiance_matrix(e);
  // Orthonormal frame around w0 to walk c = cos(angle) uniformly.
  const Vec3d t = w0.unitOrthogonal(), b = w0.cross(t);
  constexpr int N = 20001;  // odd: c = 0 is a sample
  double worst = 0, sum = 0, poly_err = 0;
  for (int i = 0; i < N; ++i) {
    const double c = -1 + 2.0 * i / (N - 1);
    const double s = std::sqrt(std::max(0.0, 1 - c * c));
    const double phi = 0.37 * i;
    const Vec3d n = c * w0 + s * (std::cos(phi) * t + std::sin(phi) * b);
    const double B = irradiance(m, n);
    poly_err = std::max(poly_err, std::abs(B - (3.0 / 32 + c / 2 + 15.0 / 32 * c * c)));
    const double err = std::abs(B - std::max(0.0, c));
    worst = std::max(worst, err);
    sum += (i == 0 || i == N - 1 ? 0.5 : 1.0) * err;  // trapezoid in c: uniform over the sphere
  }
  const double average = sum / (N - 1);
  report("directional light: max |B - max(0, n.w0)|", worst);
  report("directional light: sphere average |B - max(0, n.w0)|", average);
  EXPECT_LT(poly_err, 1e-13);  // the Funk-Hecke polynomial exactly, up to rounding
  // The error peaks at grazing (c = 0) at 3/32 = 9.4% of the peak irradiance: the "max ~9%".
  EXPECT_NEAR(worst, 3.0 / 32, 1e-12);
  // Its sphere average, integrated in closed form between the polynomial's roots, is 0.0306737:
  // the "about 3%" (slightly above it for a point light, the worst case). The trapezoid rule with
  // 20000 intervals, exact on the quadratic pieces, errs only at the four kinks, by ~1e-9.
  EXPECT_NEAR(average, 0.0306737333, 1e-6);
}

TEST(Irradiance, ProjectedLobeGivesItsAnalyticIrradiance) {
  const Lobe& lobe = kCornerLobe;
  const Mat4<double> m = irradiance_matrix(project_cube_channel<double>(lobe, 64));
  const auto A = cosine_lobe_factors<double>();
  const auto lambda = lobe.lambda();
  std::mt19937 rng(3);
  double worst = 0;
  for (int d = 0; d < 2000; ++d) {
    const Vec3d n = random_direction(rng);
    const double c = n.dot(lobe.w0);
    const double P[3] = {1, c, (3 * c * c - 1) / 2};
    double expected = 0;
    for (int l = 0; l < 3; ++l) expected += A[l] * lambda[l] * (2 * l + 1) / (4 * kPi) * P[l];
    worst = std::max(worst, std::abs(irradiance(m, n) - expected));
  }
  report("projected vMF lobe: max |B - analytic|, W = 64 (B <= 1.06)", worst);
  // |dB| <= max |dE_lm| sum_l A_l sum_m |Y_lm(n)| <= 3.8 max |dE_lm|, and max |dE_lm| < 2e-4 above.
  EXPECT_LT(worst, 8e-4);
}

}  // namespace
}  // namespace lucent::render::sh
