#include "lucent/materials/medium.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lucent::materials {
namespace {

// Marble, red channel (Jensen et al. 2001): sigma_a = 0.0021, sigma_s' = 2.19 mm^-1, eta = 1.5.
// Each expected value is worked out from the docs/DESIGN.md §4 formulas by hand (see the comment
// beside it).
TEST(DiffusionCoefficients, MarbleRedByHand) {
  const auto c = derive_coefficients(Medium<double>::from_reduced(0.0021, 2.19, 1.5));
  EXPECT_DOUBLE_EQ(c.sigma_s_reduced, 2.19);
  EXPECT_NEAR(c.sigma_t_reduced, 2.1921, 1e-15);          // 0.0021 + 2.19
  EXPECT_NEAR(c.sigma_t, 2.1921, 1e-15);                  // isotropic: sigma_t = sigma_t'
  EXPECT_NEAR(c.alpha_prime, 0.9990420145066374, 1e-15);  // 2.19 / 2.1921
  EXPECT_NEAR(c.D, 0.15206118942262367, 1e-15);           // 1 / (3 * 2.1921)
  EXPECT_NEAR(c.sigma_tr, 0.11751693494981905, 1e-15);    // sqrt(3 * 0.0021 * 2.1921)
  EXPECT_NEAR(c.z_r, 0.456183568267871, 1e-15);           // 1 / 2.1921
  EXPECT_NEAR(c.F_dr, 0.5967333333333334, 1e-15);         // -1.44/2.25 + 0.71/1.5 + 0.668 + 0.0954
  EXPECT_NEAR(c.A_dipole, 3.959497437592992, 1e-13);      // 1.59673 / 0.40327
  EXPECT_NEAR(c.z_v, 2.864527127772755, 1e-13);           // z_r + 4 A D
  EXPECT_NEAR(c.d_e, 0.32419772022491244, 1e-15);         // 2.131 D / sqrt(alpha')
  EXPECT_NEAR(c.C_phi, 0.1008648515625008, 1e-13);        // (1 - 2 C1(1.5)) / 4
  EXPECT_NEAR(c.C_E, 0.26869533564812187, 1e-12);         // (1 - 3 C2(1.5)) / 2
  EXPECT_NEAR(c.A_ddipole, 3.625170973947877, 1e-11);     // (1 - C_E) / (2 C_phi)
  EXPECT_NEAR(c.normalisation, 1.1010478808614002, 1e-12);  // 1 / (4 C_phi(1/1.5))
  EXPECT_TRUE(c.scatters());
}

TEST(DiffusionCoefficients, AnisotropicScatteringIsReduced) {
  const auto c = derive_coefficients(Medium<double>{0.5, 4.0, 0.75, 1.3});
  EXPECT_DOUBLE_EQ(c.sigma_s_reduced, 1.0);  // 4 (1 - 0.75)
  EXPECT_DOUBLE_EQ(c.sigma_t_reduced, 1.5);
  EXPECT_DOUBLE_EQ(c.sigma_t, 4.5);  // unreduced
  EXPECT_NEAR(c.alpha_prime, 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(c.D, 1.0 / 4.5, 1e-15);
  EXPECT_NEAR(c.sigma_tr, std::sqrt(3 * 0.5 * 1.5), 1e-15);
}

TEST(DiffusionCoefficients, NonScatteringChannelIsFiniteAndFlagged) {
  // The wine row: sigma_s = 0 in green and blue.
  const auto c = derive_coefficients(Medium<double>{1.6429, 0.0, 0.0, 1.3});
  EXPECT_FALSE(c.scatters());
  EXPECT_EQ(c.alpha_prime, 0.0);
  EXPECT_EQ(c.d_e, 0.0);
  for (double v : {c.D, c.sigma_tr, c.z_r, c.z_v, c.A_dipole, c.C_phi, c.C_E, c.A_ddipole}) {
    EXPECT_TRUE(std::isfinite(v));
  }
  const auto vacuum = derive_coefficients(Medium<double>{0.0, 0.0, 0.0, 1.0});
  EXPECT_FALSE(vacuum.scatters());
  EXPECT_EQ(vacuum.D, 0.0);
}

TEST(DiffusionCoefficients, DescribeThemselves) {
  const Medium<double> m{0.01, 2.0, 0.5, 1.4};
  EXPECT_NE(m.to_string().find("sigma_a=0.01/mm"), std::string::npos) << m.to_string();
  const std::string s = derive_coefficients(m).to_string();
  EXPECT_NE(s.find("sigma_tr="), std::string::npos) << s;
  EXPECT_NE(s.find("d_e="), std::string::npos) << s;
}

}  // namespace
}  // namespace lucent::materials
