// The solver's own guards (fit/src/fit_solve.h).
#include "fit_solve.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fit_start.h"
#include "lucent/materials/dipole.h"

namespace lucent::fit::detail {
namespace {

// A refit started from a fit whose sigma_a ran to 0 (an absorption its data cannot see: the exp of
// a very negative log underflows) must still run: log 0 made every refit fail at once, and the
// tabulated model's bootstrap and accuracy refits, started so, put 0 into its systematic (a 1 mm
// skim milk slab was reported with its truth 10.5 SD away).
TEST(FitSolve, AStartWhoseAbsorptionRanToZeroStillSolves) {
  ProfileData d;
  d.source = "dipole";
  d.exitance = true;             // R_d itself, per unit power entering
  d.per_incident_power = false;
  d.eta = 1.3;
  const materials::Medium<double> medium = materials::Medium<double>::from_reduced(0.01, 1.0, 1.3);
  for (int i = 0; i < 80; ++i) {
    const double r = 0.5 * std::pow(40.0, i / 79.0);
    d.radial.r_mm.push_back(r), d.radial.r_inner_mm.push_back(r), d.radial.r_outer_mm.push_back(r);
    for (int c = 0; c < 3; ++c) {
      const double v = materials::StandardDipole<double>(medium).R_d(r);
      d.radial.value[c].push_back(v);
      d.radial.standard_error[c].push_back(0.01 * v);
    }
  }
  std::array<StartValues, 3> start;
  for (StartValues& s : start) s.sigma_a = 0.0, s.sigma_s_reduced = 1.0;
  int below = 0;
  const ModelFit f = solve({d}, FitOptions{}, FitModel::kDipole, nullptr, 1.3, false,
                           {0.5, 0.5, 0.5}, start, {true, true, true}, &below);
  EXPECT_GT(f.iterations, 0) << f.message;
  for (const ChannelFit& c : f.channels) {
    EXPECT_NEAR(c.sigma_a, 0.01, 1e-4) << f.message;
    EXPECT_NEAR(c.sigma_s_reduced, 1.0, 1e-2);
  }
}

}  // namespace
}  // namespace lucent::fit::detail
