// The fit's cost functions (fit/src/fit_residuals.h): the hand-assembled ones against the AutoDiff
// ProfileResiduals they stand in for.
#include "fit_residuals.h"

#include <ceres/covariance.h>
#include <gtest/gtest.h>

#include <cmath>

namespace lucent::fit::detail {
namespace {

// 2D samples of an oblique (45 degree) capture around the entry point, in linear or log-ratio form,
// from the directional dipole at other coefficients with a ripple, so the residuals are not 0.
Observations oblique_samples(bool linear) {
  ProfileData d;
  d.incidence_polar_deg = 45;
  d.eta = 1.5;
  Observations o;
  o.radial = false;
  o.linear = linear;
  o.geometry = geometry_of(d);
  o.pixel = 0.3;
  ProfileResiduals truth{&o, FitModel::kDirectionalDipole, gauss_legendre(2)};
  for (int j = -4; j <= 4; ++j)
    for (int i = -4; i <= 4; ++i)
      if (i != 0 || j != 0) o.x.push_back(0.45 * i), o.y.push_back(0.45 * j);
  const std::size_t n = o.x.size();
  o.log_value.assign(n, 0.0), o.inv_rel_se.assign(n, 1.0), o.data_rel_se.assign(n, 1.0);
  o.value.assign(n, 0.0), o.inv_se.assign(n, 1.0), o.data_se.assign(n, 1.0);
  o.linear = true;  // residual + value = the model itself
  std::vector<double> model(n);
  const double ab[2] = {std::log(0.004), std::log(2.6)};
  truth.evaluate(ab, 0.0, 1.5, model.data());
  o.linear = linear;
  for (std::size_t k = 0; k < n; ++k) {
    const double v = model[k] * (1 + 0.05 * std::sin(3.0 * double(k)));
    o.value[k] = v, o.log_value[k] = std::log(v);
    o.data_se[k] = 0.02 * v + 1e-4, o.inv_se[k] = 1 / o.data_se[k];
    o.data_rel_se[k] = o.data_se[k] / v, o.inv_rel_se[k] = 1 / o.data_rel_se[k];
  }
  return o;
}

// The scale-free cost with Jets of 2 and an analytic scale column gives the residuals and Jacobian
// of the AutoDiff one over {ab, log scale, eta} (eta held), in both forms of the residual.
TEST(ScaledChannelCost, MatchesTheAutoDiffResidualsAndJacobian) {
  for (const bool linear : {true, false}) {
    const Observations o = oblique_samples(linear);
    const ProfileResiduals functor{&o, FitModel::kDirectionalDipole, gauss_legendre(2)};
    const int n = int(o.x.size());
    const double eta = 1.5;
    const ScaledChannelCost jet2(functor, &eta);
    ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1> jet4(
        new ProfileResiduals(functor), n);
    const double ab[2] = {std::log(0.006), std::log(2.0)}, log_scale = 0.1;
    const double* p3[3] = {ab, &log_scale, &eta};
    std::vector<double> r2(n), r4(n), j2a(2 * n), j2s(n), j4a(2 * n), j4s(n), j4e(n);
    double* jac2[2] = {j2a.data(), j2s.data()};
    double* jac4[3] = {j4a.data(), j4s.data(), j4e.data()};
    ASSERT_TRUE(jet2.Evaluate(p3, r2.data(), jac2));
    ASSERT_TRUE(jet4.Evaluate(p3, r4.data(), jac4));
    double scale_column = 0;
    for (int i = 0; i < n; ++i) {
      const double tol = 1e-9 * (1 + std::abs(r4[i]));
      EXPECT_NEAR(r2[i], r4[i], tol) << "linear " << linear << ", sample " << i;
      EXPECT_NEAR(j2a[2 * i], j4a[2 * i], 1e-9 * (1 + std::abs(j4a[2 * i])));
      EXPECT_NEAR(j2a[2 * i + 1], j4a[2 * i + 1], 1e-9 * (1 + std::abs(j4a[2 * i + 1])));
      EXPECT_NEAR(j2s[i], j4s[i], 1e-9 * (1 + std::abs(j4s[i])));
      scale_column += std::abs(j4s[i]);
    }
    EXPECT_GT(scale_column, 0);  // the column compared is not trivially 0
    std::vector<double> r0(n);
    ASSERT_TRUE(jet2.Evaluate(p3, r0.data(), nullptr));  // values only: the same residuals
    for (int i = 0; i < n; ++i) EXPECT_NEAR(r0[i], r4[i], 1e-12 * (1 + std::abs(r4[i])));
  }
}

// Solved with a calibration prior on the scale, the two costs reach the same coefficients and the
// same covariance.
TEST(ScaledChannelCost, SameSolutionAndCovarianceAsTheAutoDiffCost) {
  const Observations o = oblique_samples(true);
  const ProfileResiduals functor{&o, FitModel::kDirectionalDipole, gauss_legendre(2)};
  const int n = int(o.x.size());
  struct Answer {
    double ab[2], log_scale, covariance[9];
  };
  const auto solve_with = [&](bool two_jets) {
    Answer a{{std::log(0.01), std::log(1.5)}, 0.0, {}};
    double eta = 1.5;
    ceres::Problem problem;
    if (two_jets) {
      problem.AddResidualBlock(new ScaledChannelCost(functor, &eta), nullptr, a.ab, &a.log_scale);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
              new ProfileResiduals(functor), n),
          nullptr, a.ab, &a.log_scale, &eta);
      problem.SetParameterBlockConstant(&eta);
    }
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior{1 / 0.05}), nullptr,
        &a.log_scale);
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    so.function_tolerance = so.parameter_tolerance = 1e-14;
    so.gradient_tolerance = 1e-16;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    EXPECT_GT(summary.iterations.size(), 2u);
    ceres::Covariance covariance({});
    const std::vector<const double*> blocks = {a.ab, &a.log_scale};
    EXPECT_TRUE(covariance.Compute(blocks, &problem));
    EXPECT_TRUE(covariance.GetCovarianceMatrixInTangentSpace(blocks, a.covariance));
    return a;
  };
  const Answer two = solve_with(true), four = solve_with(false);
  EXPECT_NEAR(two.ab[0], four.ab[0], 1e-9);
  EXPECT_NEAR(two.ab[1], four.ab[1], 1e-9);
  EXPECT_NEAR(two.log_scale, four.log_scale, 1e-9);
  for (int k = 0; k < 9; ++k)
    EXPECT_NEAR(two.covariance[k], four.covariance[k], 1e-9 * std::abs(four.covariance[k]) + 1e-15)
        << "covariance entry " << k;
}

}  // namespace
}  // namespace lucent::fit::detail
