#include "lucent/materials/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lucent::materials {
namespace {

TEST(Quadrature, KnownIntegrals) {
  EXPECT_NEAR(integrate([](double x) { return std::sin(x); }, 0, std::numbers::pi), 2.0, 1e-12);
  EXPECT_NEAR(integrate([](double x) { return 1 / std::sqrt(x + 1e-12); }, 0, 1, 1e-10), 2.0, 1e-5);
  // Gaussian over the plane: int 2 pi r e^(-r^2) dr = pi.
  EXPECT_NEAR(integrate_over_plane([](double r) { return std::exp(-r * r); }, 0.5),
              std::numbers::pi, 1e-10);
  // Slowly decaying 1/(1 + r^2)^2 over the plane: pi.
  EXPECT_NEAR(integrate_over_plane([](double r) { return 1 / std::pow(1 + r * r, 2); }, 1.0, 1e-12),
              std::numbers::pi, 1e-8);
}

}  // namespace
}  // namespace lucent::materials
