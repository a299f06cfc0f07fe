// The Ceres problem of a fit: the solve over the residuals of fit_residuals.h, the covariance and
// per-channel statistics (fit_solve.h).
#include "fit_solve.h"
#include "profile_solve.h"
#include "lack_of_fit.h"
#include "system_response.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <tuple>
#include <chrono>
#include <cmath>
#include <deque>
#include <numbers>
#include <sstream>

#include "dipole_gradient.h"
#include "fit_residuals.h"
#include "fit_start.h"
#include "lucent/core/error.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"
#include "lucent/version.h"
#include "model_prediction.h"

namespace lucent::fit {
namespace {

using detail::CaptureGeometry;
using detail::ChannelResiduals;
using detail::DipoleRadialCost;
using detail::GaussLegendre;
using detail::ModelPerturbation;
using detail::Observations;
using detail::observations_for;
using detail::ProfileResiduals;
using detail::ScaledChannelCost;
using detail::ScalePrior;
using detail::start_values;
using detail::StartValues;

}  // namespace

GaussLegendre detail::gauss_legendre(int order) {
  // Golub-Welsch: nodes are the eigenvalues of the Jacobi matrix of the Legendre recurrence,
  // weights twice the squared first components of its eigenvectors; mapped from [-1, 1] to [0, 1].
  order = std::clamp(order, 1, 8);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(order, order);
  for (int k = 1; k < order; ++k) {
    const double beta = k / std::sqrt(4.0 * k * k - 1.0);
    J(k, k - 1) = J(k - 1, k) = beta;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J);
  GaussLegendre gl;
  gl.order = order;
  for (int i = 0; i < order; ++i) {
    gl.node[i] = 0.5 * (eig.eigenvalues()(i) + 1.0);
    gl.weight[i] = eig.eigenvectors()(0, i) * eig.eigenvectors()(0, i);  // 2 v^2 / 2
  }
  return gl;
}

QualitySettings quality_settings(Quality quality) {
  QualitySettings s;
  switch (quality) {
    case Quality::kFast:
      s.footprint_order = 1;
      s.max_samples_2d = 1024;
      s.function_tolerance = 1e-6;
      s.parameter_tolerance = 1e-6;
      s.max_iterations = 50;
      break;
    case Quality::kBalanced:
      s.footprint_order = 2;  // two Gauss points are exact to fourth order across a bin
      break;
    case Quality::kAccurate:
      s.footprint_order = 6;
      s.max_samples_2d = 1 << 30;
      s.function_tolerance = 1e-14;
      s.parameter_tolerance = 1e-14;
      s.max_iterations = 500;
      break;
  }
  return s;
}


namespace detail {


// The parameters in log space at the start values.
void ProfileSolve::start_parameters() {
  p.eta = eta0;
  p.log_scale = relative ? start[0].log_scale : 0.0;
  for (int c = 0; c < 3; ++c) {
    // A start from a fit whose sigma_a ran to 0 (an absorption its data cannot see: exp of a very
    // negative log underflows) is a start just above it: log 0 made every refit from it fail at
    // once, and a 1 mm skim milk slab's systematic came out 0 (its truth 10 SD away).
    const auto positive = [](double v) { return std::isfinite(v) && v > 1e-300 ? v : 1e-300; };
    p.ab[c] = {std::log(std::max(positive(start[c].sigma_a), 1e-12 * positive(start[c].sigma_s_reduced))),
               std::log(positive(start[c].sigma_s_reduced))};
  }
}

// A residual block per capture and channel (per sample under a robust loss), and the
// calibration priors.
void ProfileSolve::add_observations() {
  for (std::size_t di = 0; di < data.size(); ++di) {
    const ProfileData& d = data[di];
    const bool use_2d = d.samples_2d.has_value() && d.incidence_polar_deg > 0;
    p.calibration.push_back({0.0, 0.0, 0.0});
    for (int c = 0; c < 3; ++c) {
      if (!channels[c] || !d.channels[c]) continue;
      p.observations.push_back(observations_for(d, c, exclude[c], use_2d, q, below_noise));
      Observations& o = p.observations.back();
      attach_system_response(o, d, options.beam_sigma_mm);
      o.capture = int(di);
      if (o.log_value.empty()) continue;
      for (std::size_t i = 0; i < o.log_value.size(); ++i)
        if (!o.linear || o.value[i] >= 2 * o.data_se[i])  // the reach: samples above the noise
          range_end[c] = std::max(range_end[c], o.radial ? o.r[i] : std::hypot(o.x[i], o.y[i]));
      if (model == FitModel::kTabulated) weigh_with_table_error(o, c);
      samples[c] += int(o.log_value.size());
      // The scale this capture's channel is known to: exact (held), fitted freely (relative), or
      // within the calibration's uncertainty (a prior).
      double* scale = &p.log_scale;
      const double cal_se = d.calibrated && !relative ? d.calibration_relative_se[c] : 0.0;
      if (cal_se > 0) {
        scale = &p.calibration.back()[c];
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior{1.0 / cal_se}),
            nullptr, scale);
        record(-1, nullptr, 1);  // the prior's residual: not a sample
        calibration_blocks.emplace_back(
            scale, std::string("log calibration[") + kChannelNames[c] +
                       (data.size() > 1 ? ", input " + std::to_string(di + 1) : "") + "]");
      }
      const bool scale_free = scale != &p.log_scale || relative;
      if (options.loss == LossKind::kNone && !options.fit_ior && options.analytic_derivatives &&
          model == FitModel::kDipole && !o.linear && o.conv_nodes.empty()) {
        problem.AddResidualBlock(new DipoleRadialCost(&o, gl, &p.eta), nullptr, p.ab[c].data(),
                                 scale);
        record(c, &o, int(o.log_value.size()));
      } else if (options.loss == LossKind::kNone && !options.fit_ior && !scale_free) {
        auto* cost = new ceres::AutoDiffCostFunction<ChannelResiduals, ceres::DYNAMIC, 2>(
            new ChannelResiduals{{&o, model, gl, table, perturbation}, scale, &p.eta}, int(o.log_value.size()));
        problem.AddResidualBlock(cost, nullptr, p.ab[c].data());
        record(c, &o, int(o.log_value.size()));
      } else if (options.loss == LossKind::kNone && !options.fit_ior) {
        problem.AddResidualBlock(
            new ScaledChannelCost({&o, model, gl, table, perturbation}, &p.eta), nullptr,
            p.ab[c].data(), scale);
        record(c, &o, int(o.log_value.size()));
      } else if (options.loss == LossKind::kNone) {
        auto* cost = new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
            new ProfileResiduals{&o, model, gl, table, perturbation}, int(o.log_value.size()));
        problem.AddResidualBlock(cost, nullptr, p.ab[c].data(), scale, &p.eta);
        record(c, &o, int(o.log_value.size()));
      } else {
        add_per_sample_blocks(o, d, c, scale);
      }
    }
  }
}

// The table's own Monte Carlo error joins the data's in each weight (at the start values: the
// weights stay fixed during the solve).
void ProfileSolve::weigh_with_table_error(Observations& o, int c) {
  // values: the weights stay fixed during the solve).
  const double st = start[c].sigma_a + start[c].sigma_s_reduced;
  const double alpha = start[c].sigma_s_reduced / st;
  const materials::ObliqueProfile* ob =
      !o.radial && o.geometry.cos_incidence < 0.9999 ? table->oblique() : nullptr;
  double tx = -o.geometry.w_i[0], ty = -o.geometry.w_i[1];
  if (const double len = std::hypot(tx, ty); len > 0) tx /= len, ty /= len;
  for (std::size_t i = 0; i < o.log_value.size(); ++i) {
    const double r = o.radial ? o.r[i] : std::hypot(o.x[i], o.y[i]);
    const auto q = detail::table_quantity(o.geometry);
    const double t =
        ob ? ob->relative_se(
                 q, r * st,
                 std::atan2(std::abs(-o.x[i] * ty + o.y[i] * tx), o.x[i] * tx + o.y[i] * ty), alpha)
           : table->relative_se(q, r * st, alpha, eta0,
                                o.geometry.thickness_mm * start[c].sigma_s_reduced,
                                o.geometry.transmitted);
    const double d2 = o.data_rel_se[i] * o.data_rel_se[i];
    o.inv_rel_se[i] = std::isfinite(t) ? 1.0 / std::sqrt(d2 + t * t) : 1e-3 / std::sqrt(d2);
    if (o.linear) {  // the table's relative error of a value about max(value, se)
      const double m = std::max(o.value[i], o.data_se[i]);
      o.inv_se[i] = std::isfinite(t) ? 1.0 / std::hypot(o.data_se[i], t * m) : 1e-3 / o.data_se[i];
    }
  }
}

// Under a robust loss each sample is its own residual block.
void ProfileSolve::add_per_sample_blocks(const Observations& o, const ProfileData& d, int c,
                                         double* scale) {
  // A robust loss acts on each sample, so each gets its own block: a 2D convolution (the
  // whole grid per evaluation) cannot be split so.
  if (o.conv2d)
    throw Error(
        "--loss: a robust loss cannot go with 2D samples convolved with a system "
        "response (" +
        d.source + "); use --loss none");
  for (std::size_t i = 0; i < o.log_value.size(); ++i) {
    p.observations.push_back(o);
    Observations& one = p.observations.back();
    const auto pick = [&](std::vector<double>& v) {
      if (!v.empty()) v = {v[i]};
    };
    pick(one.r);
    pick(one.r0);
    pick(one.r1);
    pick(one.x);
    pick(one.y);
    pick(one.log_value);
    pick(one.inv_rel_se);
    pick(one.data_rel_se);
    pick(one.value);
    pick(one.inv_se);
    pick(one.data_se);
    pick(one.conv_point);
    if (const std::size_t m = one.conv_nodes.size(); m > 0)
      one.conv_weights.assign(o.conv_weights.begin() + long(i * m),
                              o.conv_weights.begin() + long((i + 1) * m));
    auto* cost = new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
        new ProfileResiduals{&one, model, gl, table, perturbation}, 1);
    ceres::LossFunction* loss =
        options.loss == LossKind::kHuber
            ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(options.loss_scale))
            : new ceres::CauchyLoss(options.loss_scale);
    problem.AddResidualBlock(cost, loss, p.ab[c].data(), scale, &p.eta);
    record(c, &one, 1);
  }
}

// Enough samples per channel; held parameters and bounds.
void ProfileSolve::check_samples_and_constrain() {
  for (int c = 0; c < 3; ++c) {
    if (channels[c] && samples[c] < 2) {
      throw Error(std::string("fit: channel ") + kChannelNames[c] + " has " +
                  std::to_string(samples[c]) + " usable samples outside the exclusion radius (" +
                  std::to_string(exclude[c]) +
                  " mm) and above the noise floor; at least 2 are needed for sigma_a and sigma_s'");
    }
  }
  for (int c = 0; hold_sigma_a && c < 3; ++c) {
    const double held = (*hold_sigma_a)[c];
    if (!(held > 0) || !problem.HasParameterBlock(p.ab[c].data())) continue;
    // Held (within 1e-9 in log space) by bounds, so the Jacobian keeps its columns.
    p.ab[c][0] = std::log(held);
    problem.SetParameterLowerBound(p.ab[c].data(), 0, p.ab[c][0] - 1e-9);
    problem.SetParameterUpperBound(p.ab[c].data(), 0, p.ab[c][0] + 1e-9);
  }
  if (problem.HasParameterBlock(&p.log_scale) && !relative)
    problem.SetParameterBlockConstant(&p.log_scale);
  if (problem.HasParameterBlock(&p.eta)) {
    if (!options.fit_ior)
      problem.SetParameterBlockConstant(&p.eta);
    else if (model == FitModel::kTabulated)
      problem.SetParameterLowerBound(&p.eta, 0, table->eta_min()),
          problem.SetParameterUpperBound(&p.eta, 0, table->eta_max());
    else
      problem.SetParameterLowerBound(&p.eta, 0, 1.0001),
          problem.SetParameterUpperBound(&p.eta, 0, 2.5);
  }
}

void ProfileSolve::run_solver() {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6 parameters: normal equations are tiny
  so.function_tolerance = q.function_tolerance;
  so.parameter_tolerance = q.parameter_tolerance;
  so.gradient_tolerance = 1e-14;
  so.max_num_iterations = options.max_iterations > 0 ? options.max_iterations : q.max_iterations;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;

  fit.model = model;
  t0 = std::chrono::steady_clock::now();
  ceres::Solve(so, &problem, &summary);
}

// Which parameters are free, and is the problem well posed at the solution?
bool ProfileSolve::evaluate_at_solution() {
  for (int c = 0; c < 3; ++c) {
    if (!channels[c]) continue;
    blocks.push_back(p.ab[c].data());
    names.push_back(std::string("log sigma_a[") + kChannelNames[c] + "]");
    names.push_back(std::string("log sigma_s'[") + kChannelNames[c] + "]");
  }
  if (relative) blocks.push_back(&p.log_scale), names.push_back("log scale");
  if (options.fit_ior) blocks.push_back(&p.eta), names.push_back("eta");
  for (const auto& [block, name] : calibration_blocks)
    blocks.push_back(block), names.push_back(name);

  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  if (summary.termination_type == ceres::FAILURE ||
      !problem.Evaluate(eo, nullptr, &residuals, nullptr, &crs) || crs.num_rows == 0) {
    // The model could not be evaluated (a non-finite residual at these start values): a fit that
    // failed, which the callers' restarts replace (its cost is infinite), never a covariance of
    // nothing.
    fit.converged = false;
    fit.message = "the model could not be evaluated from these start values (" +
                  summary.message + ")";
    fit.chi2 = INFINITY;
    fit.eta = p.eta;
    for (int c = 0; c < 3; ++c) {
      ChannelFit& ch = fit.channels[c];
      ch.sigma_a = start[c].sigma_a, ch.sigma_s_reduced = start[c].sigma_s_reduced;
      ch.start_sigma_a = start[c].sigma_a, ch.start_sigma_s_reduced = start[c].sigma_s_reduced;
      ch.residual_rms = ch.robust_residual_rms = ch.reduced_chi2 = INFINITY;
      ch.samples = samples[c];
    }
    return false;
  }
  return true;
}

ModelFit solve(const std::vector<ProfileData>& data, const FitOptions& options, FitModel model,
               const materials::TabulatedProfile* table, double eta0, bool relative,
               const std::array<double, 3>& exclude, const std::array<StartValues, 3>& start,
               std::array<bool, 3> channels, int* below_noise, ModelPerturbation perturbation,
               const std::array<double, 3>* hold_sigma_a) {
  return ProfileSolve(data, options, model, table, eta0, relative, exclude, start, channels,
                      below_noise, perturbation, hold_sigma_a)
      .run();
}

}  // namespace detail

}  // namespace lucent::fit
