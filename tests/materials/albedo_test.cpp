#include "lucent/materials/albedo.h"

#include <gtest/gtest.h>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"

namespace lucent::materials {
namespace {

TEST(Albedo, InversionRoundTripsTheClosedForm) {
  for (double eta : {1.0, 1.3, 1.5, 2.0}) {
    const double A = derive_coefficients(Medium<double>{0.0, 1.0, 0.0, eta}).A_dipole;
    for (double alpha : {0.0, 1e-6, 0.1, 0.5, 0.9, 0.99, 0.999999}) {
      const double R = dipole_total_reflectance(alpha, A);
      EXPECT_NEAR(reduced_albedo_from_total_reflectance(R, eta), alpha, 1e-9)
          << "eta " << eta << " alpha' " << alpha;
    }
  }
}

TEST(Albedo, DiffuseColourAndMeanFreePathRoundTrip) {
  // Marble-like: R_tot 0.83, l_d = 1/sigma_tr = 8.5 mm.
  for (double colour : {0.05, 0.4, 0.83, 0.97}) {
    for (double mfp : {0.1, 1.0, 8.5}) {
      const ReducedCoefficients c = coefficients_from_diffuse_colour(colour, mfp, 1.5);
      const StandardDipole<double> dipole(
          Medium<double>::from_reduced(c.sigma_a, c.sigma_s_reduced, 1.5));
      EXPECT_NEAR(dipole.total_diffuse_reflectance(), colour, 1e-10);
      EXPECT_NEAR(1.0 / dipole.coefficients().sigma_tr, mfp, 1e-9 * mfp);
    }
  }
  // Jensen's marble red: R_tot and l_d computed from the table give back the table.
  const StandardDipole<double> marble(Medium<double>::from_reduced(0.0021, 2.19, 1.5));
  const ReducedCoefficients back = coefficients_from_diffuse_colour(
      marble.total_diffuse_reflectance(), 1.0 / marble.coefficients().sigma_tr, 1.5);
  EXPECT_NEAR(back.sigma_a, 0.0021, 1e-9);
  EXPECT_NEAR(back.sigma_s_reduced, 2.19, 1e-6);
}

TEST(Albedo, RejectsValuesOutsideTheirRange) {
  EXPECT_THROW(reduced_albedo_from_total_reflectance(1.2, 1.3), Error);
  EXPECT_THROW(reduced_albedo_from_total_reflectance(-0.1, 1.3), Error);
  EXPECT_THROW(coefficients_from_diffuse_colour(0.0, 1.0, 1.3), Error);
  EXPECT_THROW(coefficients_from_diffuse_colour(1.0, 1.0, 1.3), Error);
  EXPECT_THROW(coefficients_from_diffuse_colour(0.5, 0.0, 1.3), Error);
  try {
    coefficients_from_diffuse_colour(0.5, -2.0, 1.3);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mean free path"), std::string::npos);
  }
}

}  // namespace
}  // namespace lucent::materials
