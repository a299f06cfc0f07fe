// Automatic derivatives (ceres::Jet) of the models equal central finite differences: fitting relies
// on them.
#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>

#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"

namespace lucent::materials {
namespace {

using Jet3 = ceres::Jet<double, 3>;

// Parameters: log sigma_a, log sigma_s', eta (the fit works in log space).
template <typename T>
Medium<T> medium_from(const T* p) {
  using std::exp;
  return Medium<T>::from_reduced(exp(p[0]), exp(p[1]), p[2]);
}

template <typename F>
void expect_gradient_matches(F&& f, const double* p, const char* what) {
  Jet3 jp[3];
  for (int k = 0; k < 3; ++k) jp[k] = Jet3(p[k], k);
  const Jet3 value = f(jp);
  ASSERT_TRUE(std::isfinite(value.a)) << what;
  for (int k = 0; k < 3; ++k) {
    double lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
    const double h = 1e-6 * std::max(1.0, std::abs(p[k]));
    lo[k] -= h;
    hi[k] += h;
    const double fd = (f(hi) - f(lo)) / (2 * h);
    EXPECT_NEAR(value.v[k], fd, 1e-6 * std::abs(fd) + 1e-9 * std::abs(value.a))
        << what << " d/dp" << k;
    EXPECT_TRUE(std::isfinite(value.v[k])) << what;
  }
}

TEST(Autodiff, DipoleRadialProfile) {
  for (double r : {0.0, 0.05, 1.0, 8.0}) {
    const double p[3] = {std::log(0.0041), std::log(2.62), 1.5};
    expect_gradient_matches(
        [r](const auto* q) {
          using T = std::remove_cvref_t<decltype(q[0])>;
          return StandardDipole<T>(medium_from(q)).R_d(T(r));
        },
        p, "R_d");
  }
}

TEST(Autodiff, DipoleTotalReflectance) {
  const double p[3] = {std::log(0.12), std::log(0.55), 1.3};
  expect_gradient_matches(
      [](const auto* q) {
        using T = std::remove_cvref_t<decltype(q[0])>;
        return StandardDipole<T>(medium_from(q)).total_diffuse_reflectance();
      },
      p, "R_tot");
}

TEST(Autodiff, DirectionalDipoleObliqueAndCoincident) {
  const double p[3] = {std::log(0.0090), std::log(0.70), 1.3};
  const double w = std::sqrt(0.5);
  struct Geometry {
    double xo[3];
    double wi[3];
  };
  const Geometry cases[] = {{{1.0, 0.3, 0}, {-w, 0, w}},
                            {{0, 0, 0}, {0, 0, 1}},
                            {{-2.5, 1.0, 0}, {0.2, 0.1, std::sqrt(0.95)}}};
  for (const Geometry& g : cases) {
    expect_gradient_matches(
        [&g](const auto* q) {
          using T = std::remove_cvref_t<decltype(q[0])>;
          const Vec3<T> up(T(0), T(0), T(1));
          const Vec3<T> x_o(T(g.xo[0]), T(g.xo[1]), T(g.xo[2]));
          const Vec3<T> w_i(T(g.wi[0]), T(g.wi[1]), T(g.wi[2]));
          return DirectionalDipole<T>(medium_from(q)).S_d(Vec3<T>::Zero(), up, w_i, x_o, up);
        },
        p, "S_d");
  }
}

}  // namespace
}  // namespace lucent::materials
