// The Ceres problem of a fit: the solve over the residuals of fit_residuals.h, the covariance and
// per-channel statistics (fit_solve.h).
#include "fit_solve.h"
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
#include "fit_start.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"
#include "lucent/materials/error.h"
#include "lucent/version.h"
#include "fit_residuals.h"
#include "model_prediction.h"

namespace lucent::fit {
namespace {

using detail::CaptureGeometry;
using detail::GaussLegendre;
using detail::ModelPerturbation;
using detail::start_values;
using detail::StartValues;
using detail::Observations;
using detail::ProfileResiduals;
using detail::ChannelResiduals;
using detail::DipoleRadialCost;
using detail::ScalePrior;
using detail::observations_for;

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

namespace {

const char* kChannelNames[3] = {"R", "G", "B"};



struct Problem {
  std::array<std::array<double, 2>, 3> ab{};
  double log_scale = 0;
  double eta = 1.3;
  std::deque<std::array<double, 3>> calibration;  // per profile and channel: log scale with a prior
  std::deque<Observations> observations;          // owned: residual blocks point into it (stable)
};

// Describes a null-space vector over the free parameters.
std::string describe_combination(const Eigen::VectorXd& v, const std::vector<std::string>& names) {
  std::ostringstream s;
  s.precision(2);
  bool first = true;
  for (int i = 0; i < v.size(); ++i) {
    if (std::abs(v(i)) < 0.05) continue;
    s << (first ? "" : (v(i) < 0 ? " - " : " + ")) << (first && v(i) < 0 ? "-" : "")
      << std::abs(v(i)) << " " << names[i];
    first = false;
  }
  return s.str();
}

}  // namespace

namespace detail {

ModelFit solve(const std::vector<ProfileData>& data, const FitOptions& options, FitModel model,
               const materials::TabulatedProfile* table, double eta0, bool relative,
               const std::array<double, 3>& exclude, const std::array<StartValues, 3>& start,
               std::array<bool, 3> channels, int* below_noise,
               ModelPerturbation perturbation, const std::array<double, 3>* hold_sigma_a) {
  const QualitySettings q = quality_settings(options.quality);
  const GaussLegendre gl = detail::gauss_legendre(q.footprint_order);
  Problem p;
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
  ceres::Problem problem;
  std::array<int, 3> samples{};
  std::array<double, 3> range_end{};
  std::vector<std::pair<int, int>> block_channels;  // (channel, residuals) in insertion order
  std::vector<const Observations*> block_obs;       // each block's samples (null: a prior)
  // Each residual block's samples, recorded beside block_channels.
  const auto record = [&](int c, const Observations* o, int count) {
    block_channels.emplace_back(c, count);
    block_obs.push_back(o);
  };
  std::vector<std::pair<double*, std::string>> calibration_blocks;
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
      if (model == FitModel::kTabulated) {
        // The table's own Monte Carlo error joins the data's in each weight (at the start
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
              ob ? ob->relative_se(q, r * st,
                                   std::atan2(std::abs(-o.x[i] * ty + o.y[i] * tx),
                                              o.x[i] * tx + o.y[i] * ty),
                                   alpha)
                 : table->relative_se(q, r * st, alpha, eta0,
                                      o.geometry.thickness_mm * start[c].sigma_s_reduced,
                                      o.geometry.transmitted);
          const double d2 = o.data_rel_se[i] * o.data_rel_se[i];
          o.inv_rel_se[i] = std::isfinite(t) ? 1.0 / std::sqrt(d2 + t * t) : 1e-3 / std::sqrt(d2);
          if (o.linear) {  // the table's relative error of a value about max(value, se)
            const double m = std::max(o.value[i], o.data_se[i]);
            o.inv_se[i] = std::isfinite(t) ? 1.0 / std::hypot(o.data_se[i], t * m)
                                           : 1e-3 / o.data_se[i];
          }
        }
      }
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
      } else if (options.loss == LossKind::kNone) {
        auto* cost = new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
            new ProfileResiduals{&o, model, gl, table, perturbation}, int(o.log_value.size()));
        problem.AddResidualBlock(cost, nullptr, p.ab[c].data(), scale, &p.eta);
        record(c, &o, int(o.log_value.size()));
      } else {
        // A robust loss acts on each sample, so each gets its own block: a 2D convolution (the
        // whole grid per evaluation) cannot be split so.
        if (o.conv2d)
          throw Error("--loss: a robust loss cannot go with 2D samples convolved with a system "
                      "response (" + d.source + "); use --loss none");
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
    }
  }
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

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6 parameters: normal equations are tiny
  so.function_tolerance = q.function_tolerance;
  so.parameter_tolerance = q.parameter_tolerance;
  so.gradient_tolerance = 1e-14;
  so.max_num_iterations = options.max_iterations > 0 ? options.max_iterations : q.max_iterations;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;

  ModelFit fit;
  fit.model = model;
  const auto t0 = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  // Which parameters are free, and is the problem well posed at the solution?
  std::vector<double*> blocks;
  std::vector<std::string> names;
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
  ceres::CRSMatrix crs;
  std::vector<double> residuals;  // in residual-block order, for the per-channel statistics below
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
    return fit;
  }
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) J(row, crs.cols[k]) = crs.values[k];
  }
  Eigen::MatrixXd covariance;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double smax = sv.size() ? sv(0) : 0;
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(sv.size());
  for (int i = 0; i < sv.size(); ++i) {
    // A direction is undetermined when the data cannot pin it within a factor e (its standard
    // deviation in log space, 1 / s, exceeds 1), or when it is numerically null.
    if (sv(i) > 1e-10 * smax && sv(i) > 1.0) {
      inv2(i) = 1.0 / (sv(i) * sv(i));
    } else {
      fit.undetermined.push_back(describe_combination(svd.matrixV().col(i), names));
    }
  }
  // A parameter that leans on an undetermined direction is known to no better than a factor e:
  // its log-space variance is at least 1 (reported, never a deceptive 0).
  std::vector<double> floor_var(std::size_t(sv.size() ? svd.matrixV().rows() : 0), 0.0);
  for (int i = 0; i < sv.size(); ++i) {
    if (inv2(i) != 0) continue;
    for (int j = 0; j < svd.matrixV().rows(); ++j)
      if (std::abs(svd.matrixV()(j, i)) > 0.3) floor_var[std::size_t(j)] = 1.0;
  }
  // (J^T J)^+ from the SVD: the covariance of the free parameters when the standard errors are
  // honest; directions the data does not determine are left out and reported instead.
  covariance = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  fit.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  fit.beam_sigma_mm = options.beam_sigma_mm;
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  fit.iterations = int(summary.iterations.size()) - 1;
  fit.message = summary.message;
  fit.chi2 = 2 * summary.final_cost;
  fit.eta = p.eta;
  fit.scale = std::exp(p.log_scale);
  for (int c = 0; c < 3; ++c) fit.calibration_scale[c] = std::exp(p.calibration.front()[c]);
  int k = 0;
  for (int c = 0; c < 3; ++c) {
    ChannelFit& ch = fit.channels[c];
    ch.start_sigma_a = start[c].sigma_a;
    ch.start_sigma_s_reduced = start[c].sigma_s_reduced;
    if (!channels[c]) continue;
    ch.sigma_a = std::exp(p.ab[c][0]);
    ch.sigma_s_reduced = std::exp(p.ab[c][1]);
    const double va = std::max(covariance(k, k), floor_var[std::size_t(k)]);
    const double vs = std::max(covariance(k + 1, k + 1), floor_var[std::size_t(k) + 1]);
    ch.sd_sigma_a = ch.sigma_a * std::sqrt(std::max(0.0, va));  // delta method from log space
    ch.sd_sigma_s_reduced = ch.sigma_s_reduced * std::sqrt(std::max(0.0, vs));
    if (floor_var[std::size_t(k)] > 0 && range_end[c] > 0) {
      // An undetermined sigma_a may have run to ~0: bound it instead by the absorption a profile
      // of this reach would just show, sigma_tr R = 1, i.e. sigma_a = 1 / (3 sigma_t' R^2).
      const double st = ch.sigma_a + ch.sigma_s_reduced;
      ch.sd_sigma_a = std::max(ch.sd_sigma_a, 1.0 / (3 * st * range_end[c] * range_end[c]));
    }
    ch.correlation = va > 0 && vs > 0 ? covariance(k, k + 1) / std::sqrt(va * vs) : 0.0;
    ch.samples = samples[c];
    k += 2;
  }
  if (relative) fit.sd_scale = fit.scale * std::sqrt(std::max(0.0, covariance(k, k))), ++k;
  if (options.fit_ior) fit.sd_eta = std::sqrt(std::max(0.0, covariance(k, k))), ++k;
  k += int(calibration_blocks.size());
  fit.parameters = k;
  // Per-channel chi^2 and rms from the residuals at the solution.
  {
    std::size_t offset = 0;
    std::array<double, 3> chi2{};
    std::array<std::vector<double>, 3> magnitudes;  // |residual| per sample, for the median
    // Single pixels' noise is not independent from pixel to pixel (a simulated capture's Monte
    // Carlo noise: one photon path scores along millimetres; a real sample's texture), nor always
    // as small as the camera model says. The design effect measures both: over square cells of
    // side L, D = sum (sum of a cell's residuals)^2 / samples, 1 for independent residuals of unit
    // variance. The largest D over L = 1, 2, 4, 8 mm scales the statistical variance like the Birge
    // ratio does (which is D at L = 0).
    std::array<double, 3> design{1.0, 1.0, 1.0};
    std::array<std::map<std::tuple<int, double, long, long>, double>, 3> cells;
    std::array<int, 3> pixel_samples{};
    for (std::size_t b = 0; b < block_channels.size(); ++b) {
      const auto [c, count] = block_channels[b];
      const Observations* o = block_obs[b];
      for (int i = 0; i < count; ++i, ++offset) {
        if (c < 0) continue;
        chi2[c] += residuals[offset] * residuals[offset];
        magnitudes[c].push_back(std::abs(residuals[offset]));
        if (!o || !o->linear) continue;
        ++pixel_samples[c];
        for (double side : {1.0, 2.0, 4.0, 8.0})
          cells[c][{o->capture, side, long(std::floor(o->x[i] / side)),
                    long(std::floor(o->y[i] / side))}] += residuals[offset];
      }
    }
    for (int c = 0; c < 3; ++c) {
      if (pixel_samples[c] < 50) continue;
      std::map<double, double> sum2;
      for (const auto& [key, sum] : cells[c]) sum2[std::get<1>(key)] += sum * sum;
      for (const auto& [side, ss] : sum2) design[c] = std::max(design[c], ss / pixel_samples[c]);
    }
    for (int c = 0; c < 3; ++c) {
      std::vector<double>& m = magnitudes[c];
      if (m.empty()) continue;
      std::nth_element(m.begin(), m.begin() + m.size() / 2, m.end());
      // 1.4826 x the median |r|: the rms a Gaussian with that median has; a few outliers leave
      // it alone (they are the robust loss's business), a model that misses the data does not.
      fit.channels[c].robust_residual_rms = 1.4826 * m[m.size() / 2];
    }
    // fit.chi2 (AIC, BIC) keeps the calibration priors' share: a model that reaches the data only
    // by rescaling the calibration far beyond its uncertainty pays for it.
    for (int c = 0; c < 3; ++c) {
      ChannelFit& ch = fit.channels[c];
      ch.chi2 = chi2[c];
      ch.residual_rms = samples[c] ? std::sqrt(chi2[c] / samples[c]) : 0.0;
      // Lack of fit: a reduced chi^2 above 1 says the residuals are larger than the standard
      // errors allow, so the statistical spread is that much larger (Birge ratio).
      ch.reduced_chi2 = samples[c] > 2 ? chi2[c] / (samples[c] - 2) : 0.0;
      ch.design_effect = design[c];
      const double birge = std::sqrt(std::max({1.0, ch.reduced_chi2, design[c]}));
      ch.sd_sigma_a *= birge;
      ch.sd_sigma_s_reduced *= birge;
      ch.sd_stat_sigma_a = ch.sd_sigma_a;
      ch.sd_stat_sigma_s_reduced = ch.sd_sigma_s_reduced;
      ch.exclude_radius_mm = exclude[c];
    }
  }
  // The usable range of each channel: from its exclusion radius to its last fitted sample.
  {
    for (int c = 0; c < 3; ++c) fit.channels[c].range_end_mm = range_end[c];
    for (ChannelFit& ch : fit.channels) {
      const double sigma_tr = std::sqrt(3 * ch.sigma_a * (ch.sigma_a + ch.sigma_s_reduced));
      ch.range_diffusion_lengths =
          std::max(0.0, ch.range_end_mm - ch.exclude_radius_mm) * sigma_tr;
    }
  }
  // "Converged" means the data fits. Ceres' CONVERGENCE only says the steps stopped changing the
  // cost; a channel whose residuals stay far beyond its standard errors is a solution that misses
  // the data (a model that cannot describe it, a wrong index, a floor in the profile).
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& ch = fit.channels[c];
    if (!channels[c] || samples[c] == 0 || !(ch.robust_residual_rms > kMaxFittedRms)) continue;
    std::ostringstream why;
    why.precision(3);
    why << "the solver stopped, but the model misses the data: channel " << "RGB"[c]
        << "'s residuals are " << ch.robust_residual_rms
        << " standard errors (robust rms; a fit that describes its data has about 1)";
    fit.converged = false;
    fit.message = why.str();
    break;
  }
  // The accurate model is transport in a semi-infinite sample under a pencil beam: runs of one sign
  // along the radius that noise does not make say the sample, beam or lens are not that (the
  // diffusion models' own error is carried as their systematic instead).
  if (model == FitModel::kTabulated) {
    std::size_t offset = 0;
    for (std::size_t b = 0; b < block_channels.size(); ++b) {
      const auto [c, count] = block_channels[b];
      const Observations* o = block_obs[b];
      const std::size_t at = offset;
      offset += std::size_t(count);
      // Radial bins (of an annulus, or of pixel averages: then o->radial is false, o->r kept).
      if (c < 0 || !o || o->linear || int(o->r.size()) != count) continue;
      // The table's share of each residual's error (its weight holds data and table in
      // quadrature): sqrt(1 - (data's relative error x weight)^2).
      std::vector<double> model_share(std::size_t(count), 0.0);
      for (int i = 0; i < count; ++i) {
        const double a = o->data_rel_se[std::size_t(i)] * o->inv_rel_se[std::size_t(i)];
        model_share[std::size_t(i)] = std::sqrt(std::max(0.0, 1 - a * a));
      }
      const RadialStructure s =
          radial_structure(o->r, residuals.data() + at, count, model_share.data());
      ChannelFit& ch = fit.channels[c];
      if (s.segments() == 0 || !(s.z > ch.structure_z)) continue;
      ch.structure_z = s.z;
      if (s.z > kMaxStructureZ && fit.converged) {
        fit.converged = false;
        fit.message = lack_of_fit_reason(s, "RGB"[c]);
      }
    }
  }
  fit.samples = samples[0] + samples[1] + samples[2];
  fit.aic = fit.chi2 + 2.0 * fit.parameters;
  fit.bic = fit.chi2 + fit.parameters * std::log(std::max(1, fit.samples));
  return fit;
}


}  // namespace detail

}  // namespace lucent::fit
