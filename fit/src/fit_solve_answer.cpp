// The stages of a solve that judge its answer (profile_solve.h): the covariance of the free
// parameters and the fitted values, each channel's statistics (chi^2, the design effect, the robust
// residual rms), and the check that the model fits its data.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "lack_of_fit.h"
#include "profile_solve.h"

namespace lucent::fit::detail {

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

// The covariance of the free parameters from the Jacobian's SVD, and the fitted values.
void ProfileSolve::covariance_and_values() {
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
}

void ProfileSolve::channel_statistics() {
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
}

void ProfileSolve::check_fit() {
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
}

}  // namespace lucent::fit::detail
