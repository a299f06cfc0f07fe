// The fit's hand-written dipole Jacobian against the templated model (values) and ceres::Jet
// (derivatives), and the two derivative modes of the fit against each other.
#include "dipole_gradient.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>

#include "lucent/fit/fit.h"
#include "lucent/materials/dipole.h"

namespace lucent::fit {
namespace {

TEST(DipoleGradient, MatchesTheModelAndItsAutomaticDerivatives) {
  using Jet = ceres::Jet<double, 2>;
  for (const std::string name : {"marble", "ketchup", "skin1", "cream", "beer"}) {
    const materials::Material m = materials::load_material(name);
    for (int c = 0; c < 3; ++c) {
      const detail::DipoleGradientModel model(m.sigma_a[c], m.sigma_s_reduced[c], m.ior);
      const materials::StandardDipole<Jet> jet(materials::Medium<Jet>::from_reduced(
          exp(Jet(std::log(m.sigma_a[c]), 0)), exp(Jet(std::log(m.sigma_s_reduced[c]), 1)),
          Jet(m.ior)));
      for (double r : {0.0, 0.01, 0.3, 1.0, 4.0, 25.0}) {
        const detail::DipoleGradient g = model.at(r);
        const Jet expected = jet.R_d(Jet(r));
        EXPECT_NEAR(g.value, expected.a, 1e-12 * expected.a) << name << c << " r " << r;
        EXPECT_NEAR(g.d_log_sigma_a, expected.v[0], 1e-10 * std::abs(expected.v[0]) + 1e-300);
        EXPECT_NEAR(g.d_log_sigma_s, expected.v[1], 1e-10 * std::abs(expected.v[1]) + 1e-300);
      }
    }
  }
}

TEST(DipoleGradient, AnalyticAndAutomaticFitsAgree) {
  const materials::Material m = materials::load_material("potato");
  ProfileData d;
  d.source = "model";
  d.eta = m.ior;
  for (int i = 0; i < 80; ++i) {
    const double r0 = 0.25 * i, r1 = 0.25 * (i + 1);
    d.radial.r_inner_mm.push_back(r0);
    d.radial.r_outer_mm.push_back(r1);
    d.radial.r_mm.push_back(0.5 * (r0 + r1));
    for (int c = 0; c < 3; ++c) {
      // A profile the model cannot match exactly (a 3% ripple), so the two solutions are compared
      // at a non-trivial minimum.
      const double v = materials::StandardDipole<double>(m.medium(c)).R_d(0.5 * (r0 + r1)) *
                       (1 + 0.03 * std::sin(1.7 * i));
      d.radial.value[c].push_back(v);
      d.radial.standard_error[c].push_back(0.02 * v);
    }
  }
  FitOptions o;
  o.model = FitModel::kDipole;
  o.quality = Quality::kAccurate;
  o.analytic_derivatives = true;
  const FitResult analytic = fit_profiles({d}, o);
  o.analytic_derivatives = false;
  const FitResult automatic = fit_profiles({d}, o);
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& a = analytic.chosen.channels[c];
    const ChannelFit& b = automatic.chosen.channels[c];
    // Same minimum: the solutions differ by far less than their uncertainty (the solver's stopping
    // tolerance, not the derivatives, sets the last digits).
    EXPECT_NEAR(a.sigma_a, b.sigma_a, 1e-3 * b.sd_sigma_a);
    EXPECT_NEAR(a.sigma_s_reduced, b.sigma_s_reduced, 1e-3 * b.sd_sigma_s_reduced);
    EXPECT_NEAR(a.sd_sigma_a, b.sd_sigma_a, 1e-4 * b.sd_sigma_a);
    EXPECT_NEAR(a.correlation, b.correlation, 1e-4);
  }
}

}  // namespace
}  // namespace lucent::fit
