#include "lucent/materials/dipole.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lucent/materials/material.h"
#include "lucent/materials/quadrature.h"

namespace lucent::materials {
namespace {

TEST(StandardDipole, MarbleRedAtOneMillimetreByHand) {
  // alpha'/(4 pi) [z_r (1 + s_tr d_r) e^(-s_tr d_r) / d_r^3 + z_v (...)] with the coefficients of
  // medium_test's MarbleRedByHand, d_r = sqrt(1 + z_r^2), d_v = sqrt(1 + z_v^2).
  const StandardDipole<double> dipole(Medium<double>::from_reduced(0.0021, 2.19, 1.5));
  EXPECT_NEAR(dipole.R_d(1.0), 0.03484669173791536, 1e-15);
  EXPECT_NEAR(dipole.S_d(1.0), 0.03484669173791536 / std::numbers::pi, 1e-15);
  EXPECT_NEAR(dipole.total_diffuse_reflectance(), 0.8301914562772919, 1e-14);
}

TEST(StandardDipole, PlaneIntegralEqualsClosedFormForEveryBundledMaterial) {
  for (const std::string& name : library_material_names()) {
    const Material material = load_material(name);
    for (int channel = 0; channel < 3; ++channel) {
      const StandardDipole<double> dipole(material.medium(channel));
      const double closed = dipole.total_diffuse_reflectance();
      if (!dipole.coefficients().scatters()) {
        EXPECT_EQ(closed, 0.0);
        EXPECT_EQ(dipole.R_d(0.5), 0.0);
        continue;
      }
      const double numeric = integrate_over_plane([&](double r) { return dipole.R_d(r); },
                                                  dipole.coefficients().z_r, 1e-12);
      EXPECT_NEAR(numeric, closed, 1e-6 * closed) << name << " channel " << channel;
    }
  }
}

TEST(StandardDipole, TotalIsMonotonicInAlbedoAndBounded) {
  double previous = -1;
  for (double alpha = 0.0; alpha <= 1.0; alpha += 0.001) {
    const double R = dipole_total_reflectance(alpha, 3.0);
    EXPECT_GT(R, previous);
    EXPECT_LE(R, 1.0);
    previous = R;
  }
  EXPECT_DOUBLE_EQ(dipole_total_reflectance(1.0, 3.0), 1.0);
}

TEST(StandardDipole, ProfileDecreasesAndIsFiniteAtTheOrigin) {
  const StandardDipole<double> dipole(Medium<double>::from_reduced(0.0024, 0.68, 1.3));
  EXPECT_TRUE(std::isfinite(dipole.R_d(0.0)));
  double previous = dipole.R_d(0.0);
  for (double r = 0.01; r < 100; r *= 1.1) {
    const double value = dipole.R_d(r);
    EXPECT_LT(value, previous) << "r " << r;
    previous = value;
  }
}

TEST(StandardDipole, FarFieldDecaysWithSigmaTr) {
  // For r >> z_v, R_d ~ e^(-sigma_tr r) (1 + sigma_tr r) / r^3: the log-slope tends to -sigma_tr.
  const StandardDipole<double> dipole(Medium<double>::from_reduced(0.05, 1.0, 1.3));
  const double r = 200.0, h = 1.0;
  const double slope = (std::log(dipole.R_d(r + h)) - std::log(dipole.R_d(r - h))) / (2 * h);
  const double s = dipole.coefficients().sigma_tr;
  const double expected = -s + s / (1 + s * r) - 3 / r;
  EXPECT_NEAR(slope, expected, 1e-3 * s);
}

TEST(StandardDipole, DescribesItself) {
  const StandardDipole<double> dipole(Medium<double>::from_reduced(0.0021, 2.19, 1.5));
  EXPECT_NE(dipole.to_string().find("StandardDipole{"), std::string::npos);
  EXPECT_NE(dipole.to_string().find("z_v="), std::string::npos);
}

}  // namespace
}  // namespace lucent::materials
