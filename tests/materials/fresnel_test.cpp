#include "lucent/materials/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lucent/materials/quadrature.h"

namespace lucent::materials {
namespace {

// Transmittance from the amplitude transmission coefficients, independent of 1 - R:
// T = (eta cos_t / cos_i) (t_s^2 + t_p^2) / 2.
double transmittance_from_amplitudes(double cos_i, double eta) {
  const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 0.0;
  const double cos_t = std::sqrt(1 - sin2_t);
  const double t_s = 2 * cos_i / (cos_i + eta * cos_t);
  const double t_p = 2 * cos_i / (eta * cos_i + cos_t);
  return eta * cos_t / cos_i * 0.5 * (t_s * t_s + t_p * t_p);
}

TEST(Fresnel, NormalIncidenceMatchesClosedForm) {
  for (double eta : {1.0, 1.3, 1.5, 2.5, 0.8}) {
    const double expected = std::pow((eta - 1) / (eta + 1), 2);
    EXPECT_NEAR(fresnel_reflectance(1.0, eta), expected, 1e-15) << "eta " << eta;
  }
  EXPECT_NEAR(fresnel_reflectance(1.0, 1.5), 0.04, 1e-15);
}

TEST(Fresnel, BrewsterAngleCancelsParallelPolarisation) {
  const double eta = 1.5;
  const double theta_b = std::atan(eta);
  const double cos_i = std::cos(theta_b);
  const double cos_t = std::sqrt(1 - (1 - cos_i * cos_i) / (eta * eta));
  const double r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  EXPECT_NEAR(fresnel_reflectance(cos_i, eta), 0.5 * r_s * r_s, 1e-15);
}

TEST(Fresnel, TotalInternalReflectionAndGrazing) {
  const double eta = 1 / 1.5;  // glass to air
  const double critical_cos = std::sqrt(1 - eta * eta);
  EXPECT_EQ(fresnel_reflectance(critical_cos * 0.999, eta), 1.0);
  EXPECT_LT(fresnel_reflectance(critical_cos * 1.001, eta), 1.0);
  EXPECT_NEAR(fresnel_reflectance(0.0, 1.5), 1.0, 1e-15);
  EXPECT_NEAR(fresnel_reflectance(1e-9, 1.5), 1.0, 1e-8);
}

TEST(Fresnel, EnergyIsConservedAgainstAmplitudeTransmittance) {
  for (double eta : {1.0, 1.2, 1.5, 2.5, 0.9, 0.6}) {
    for (double cos_i = 0.01; cos_i <= 1.0; cos_i += 0.01) {
      const double R = fresnel_reflectance(cos_i, eta);
      EXPECT_NEAR(R + transmittance_from_amplitudes(cos_i, eta), 1.0, 1e-12)
          << "eta " << eta << " cos_i " << cos_i;
      EXPECT_NEAR(fresnel_transmittance(cos_i, eta), 1.0 - R, 0.0);
    }
  }
}

TEST(Fresnel, ReflectanceIsReciprocal) {
  // The same interface crossed the other way: R(theta_i, eta) = R(theta_t, 1 / eta).
  const double eta = 1.4;
  for (double cos_i = 0.05; cos_i <= 1.0; cos_i += 0.05) {
    const double cos_t = std::sqrt(1 - (1 - cos_i * cos_i) / (eta * eta));
    EXPECT_NEAR(fresnel_reflectance(cos_i, eta), fresnel_reflectance(cos_t, 1 / eta), 1e-14);
  }
}

TEST(Fresnel, FloatMatchesDouble) {
  for (double cos_i = 0.0; cos_i <= 1.0; cos_i += 0.001) {
    EXPECT_NEAR(fresnel_reflectance<float>(float(cos_i), 1.5f), fresnel_reflectance(cos_i, 1.5),
                2e-6);
  }
}

// Moments of the Fresnel reflectance seen from inside a medium of relative index eta (light leaving
// it meets relative index 1 / eta), computed by quadrature from their definitions.
double moment(double eta, int power_of_cos) {
  return integrate(
      [&](double theta) {
        return fresnel_reflectance(std::cos(theta), 1 / eta) * std::sin(theta) *
               std::pow(std::cos(theta), power_of_cos);
      },
      0.0, std::numbers::pi / 2, 1e-12);
}

TEST(Fresnel, MomentFitsAgreeWithQuadratureWithinOnePercent) {
  for (double eta = 1.0; eta <= 2.0 + 1e-9; eta += 0.02) {
    const double c_phi = (1 - 2 * moment(eta, 1)) / 4;
    const double c_e = (1 - 3 * moment(eta, 2)) / 2;
    EXPECT_NEAR(C_phi(eta), c_phi, 0.01 * c_phi) << "eta " << eta;
    EXPECT_NEAR(C_E(eta), c_e, 0.01 * c_e) << "eta " << eta;
  }
  // Beyond 2 d'Eon and Irving's fits drift: measured 0.6% at 2.0, 1.1% (C_phi) and 3.9% (C_E) at
  // 2.5. Kept (the directional dipole is the authors' formulation, fits included); bounded here so
  // that a change to them is seen.
  for (double eta = 2.0; eta <= 2.5 + 1e-9; eta += 0.05) {
    const double c_phi = (1 - 2 * moment(eta, 1)) / 4;
    const double c_e = (1 - 3 * moment(eta, 2)) / 2;
    EXPECT_NEAR(C_phi(eta), c_phi, 0.012 * c_phi) << "eta " << eta;
    EXPECT_NEAR(C_E(eta), c_e, 0.04 * c_e) << "eta " << eta;
  }
}

TEST(Fresnel, MomentsBelowOneAreTheQuadratureOfTheirDefinition) {
  // eta < 1 (a sample optically thinner than its surroundings, e.g. in water or oil): the moments
  // against an adaptive quadrature of the definitions. C2 is a 16-node rule there (exact to 1e-10),
  // C1 the fit's own branch for n <= 1 (measured within 3e-5 of the quadrature). The old single
  // C2 fit gave C_E(0.8) = 0.12 and C_E(0.75) = -0.40 where the truth is 0.486 and 0.480.
  for (double eta = 0.5; eta < 1.0; eta += 0.01) {
    EXPECT_NEAR(fresnel_moment_C2(eta), moment(eta, 2), 1e-9) << "eta " << eta;
    EXPECT_NEAR(fresnel_moment_C1(eta), moment(eta, 1), 5e-5) << "eta " << eta;
    const double c_e = (1 - 3 * moment(eta, 2)) / 2;
    EXPECT_GT(C_E(eta), 0.43) << "eta " << eta;
    EXPECT_LE(C_E(eta), 0.5) << "eta " << eta;
    EXPECT_NEAR(C_E(eta), c_e, 1e-8) << "eta " << eta;
  }
  // Continuous across eta = 1 within the eta >= 1 fit's own offset there (C_E(1) = 0.5034).
  EXPECT_NEAR(C_E(0.9999), C_E(1.0), 0.004);
  // Differentiable for fits that free eta: float and double agree, and the Jet-free path is
  // monotone (more contrast, more reflection, less flux across).
  EXPECT_NEAR(double(C_E<float>(0.8f)), C_E(0.8), 1e-6);
  for (double eta = 0.5; eta < 0.99; eta += 0.01) EXPECT_LT(C_E(eta), C_E(eta + 0.01));
}

TEST(Fresnel, DiffuseReflectanceFitIsTheFirstMoment) {
  // F_dr = 2 C1: Jensen's fit against quadrature. It is a fit: measured here it is within 0.6% of
  // F_dr up to eta = 2.5, plus the fit's own offset of 0.0016 at eta = 1 where F_dr itself is 0.
  for (double eta = 1.0; eta <= 2.5 + 1e-9; eta += 0.05) {
    const double f_dr = 2 * moment(eta, 1);
    EXPECT_NEAR(diffuse_fresnel_reflectance(eta), f_dr, 0.007 * f_dr + 0.002) << "eta " << eta;
  }
  for (double eta = 0.6; eta < 1.0; eta += 0.05) {
    const double f_dr = 2 * moment(eta, 1);
    EXPECT_NEAR(diffuse_fresnel_reflectance(eta), f_dr, 0.01) << "eta " << eta;
  }
  // The thesis's misprinted 0.0036 would miss by 0.06 eta: make sure we use 0.0636.
  EXPECT_NEAR(diffuse_fresnel_reflectance(1.3), -1.44 / 1.69 + 0.71 / 1.3 + 0.668 + 0.0636 * 1.3,
              1e-15);
}

}  // namespace
}  // namespace lucent::materials
